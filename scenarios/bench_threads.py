"""``python -m scenarios.bench_threads`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_threads`."""
from .numerics.bench_threads import main

if __name__ == "__main__":
    raise SystemExit(main())

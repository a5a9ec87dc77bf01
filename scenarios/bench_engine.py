"""``python -m scenarios.bench_engine`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_engine`."""
from .numerics.bench_engine import main

if __name__ == "__main__":
    raise SystemExit(main())

"""``python -m scenarios.bench_steps`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_steps`."""
from .numerics.bench_steps import main

if __name__ == "__main__":
    raise SystemExit(main())

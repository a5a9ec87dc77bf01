"""``python -m scenarios.bench_statistics`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_statistics`."""
from .numerics.bench_statistics import main

if __name__ == "__main__":
    raise SystemExit(main())

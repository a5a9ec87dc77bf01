"""``python -m scenarios.bench_study`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_study`."""
from .numerics.bench_study import main

if __name__ == "__main__":
    raise SystemExit(main())

"""``python -m scenarios.bench_static`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_static`."""
from .numerics.bench_static import main

if __name__ == "__main__":
    raise SystemExit(main())

"""``python -m scenarios.bench_breakdown`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_breakdown`."""
from .numerics.bench_breakdown import main

if __name__ == "__main__":
    raise SystemExit(main())

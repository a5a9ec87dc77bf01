"""``python -m scenarios.bench_reads`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_reads`."""
from .numerics.bench_reads import main

if __name__ == "__main__":
    raise SystemExit(main())

"""``python -m scenarios.bench_batches`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_batches`."""
from .numerics.bench_batches import main

if __name__ == "__main__":
    raise SystemExit(main())

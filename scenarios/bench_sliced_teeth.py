"""``python -m scenarios.bench_sliced_teeth`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_sliced_teeth`."""
from .numerics.bench_sliced_teeth import main

if __name__ == "__main__":
    raise SystemExit(main())

"""``python -m scenarios.bench_sliced`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_sliced`."""
from .numerics.bench_sliced import main

if __name__ == "__main__":
    raise SystemExit(main())

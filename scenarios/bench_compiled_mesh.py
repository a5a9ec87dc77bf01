"""``python -m scenarios.bench_compiled_mesh`` as documented: a shim, the code is :mod:`scenarios.numerics.bench_compiled_mesh`."""
from .numerics.bench_compiled_mesh import main

if __name__ == "__main__":
    raise SystemExit(main())

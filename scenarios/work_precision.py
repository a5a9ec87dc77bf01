"""``python -m scenarios.work_precision`` as documented: a shim, the code is :mod:`scenarios.numerics.work_precision`."""
from .numerics.work_precision import main

if __name__ == "__main__":
    raise SystemExit(main())

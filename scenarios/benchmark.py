"""``python -m scenarios.benchmark`` as documented: a shim, the code is :mod:`scenarios.numerics.benchmark`."""
from .numerics.benchmark import main

if __name__ == "__main__":
    raise SystemExit(main())

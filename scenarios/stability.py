"""``python -m scenarios.stability`` as documented: a shim, the code is :mod:`scenarios.numerics.stability`."""
from .numerics.stability import main

if __name__ == "__main__":
    raise SystemExit(main())

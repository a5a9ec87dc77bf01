"""``python -m scenarios.warm`` as documented: a shim, the code is :mod:`scenarios.numerics.warm`."""
from .numerics.warm import main

if __name__ == "__main__":
    raise SystemExit(main())

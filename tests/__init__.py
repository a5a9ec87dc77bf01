"""The test suite, one package per source package (mbd/, components/, scenarios/, viz/); the modules at this level
check what crosses them (architecture, documents, commands, the output files' names, the tour notebook). Shared
helpers live in tests.support and are imported from there (``from tests.support.strategies import ...``)."""

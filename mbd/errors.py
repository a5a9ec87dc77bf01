"""Exceptions raised by the engine; each message names the parameter or element at fault."""


class ModelError(ValueError):
    """Invalid model data (masses, indices, parameters)."""


class IntegrationError(RuntimeError):
    """The integrator could not continue (step too small, non-finite forces). ``counters``: the run's
    counters (a dict as in SimResult) up to the failure, set by :func:`mbd.simulate`."""

    def __init__(self, message: str, state=None, saved_to=None, counters=None):
        super().__init__(message)
        self.state = state
        self.saved_to = saved_to
        self.counters = counters

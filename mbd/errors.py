"""Exceptions raised by the engine; each message names the parameter or element at fault."""


class ModelError(ValueError):
    """Invalid model data (masses, indices, parameters)."""


class IntegrationError(RuntimeError):
    """The integrator could not continue (step too small, non-finite forces)."""

    def __init__(self, message: str, state=None, saved_to=None):
        super().__init__(message)
        self.state = state
        self.saved_to = saved_to

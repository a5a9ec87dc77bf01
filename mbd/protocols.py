"""What :func:`mbd.simulate` asks of the objects it is handed: a step-size :class:`Controller`, :class:`Observer`\\ s
and a :class:`Recorder`, as ``typing.Protocol``\\ s — any object with these methods will do (structural typing);
subclassing :class:`Observer` gives its defaults. ``simulate`` checks its arguments against them when it starts
(:func:`require`), so a wrong object fails at once, naming the argument and the missing method, not deep in a step.

:class:`Recorder` here is the protocol; ``mbd.Recorder`` (:class:`mbd.recorder.Recorder`) is the engine's
implementation of it (samples at a fixed rate, streamed to a netCDF file).
"""
from __future__ import annotations

import inspect
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from .errors import ModelError

if TYPE_CHECKING:         # annotations only: the engine modules import this one
    from .assembly import System
    from .model import Model, State

__all__ = ["Controller", "Observer", "Recorder", "require"]


@runtime_checkable
class Controller(Protocol):
    """Chooses the step size and alone accepts or rejects a step (:mod:`mbd.control`: FixedStep, Adaptive; only
    those two run on the compiled path). An optional attribute ``h_min`` [s]: a rejected step proposing less
    ends the run with an IntegrationError (default 0)."""

    def initial(self) -> float:
        """The first step size [s]."""
        ...

    def decide(self, h: float, converged: bool, error: float) -> tuple[bool, float]:
        """(accept the step of size h?, the next step size [s]) from Newton's convergence and the scaled
        local error estimate (≤ 1: within tolerance)."""
        ...


@runtime_checkable
class Observer(Protocol):
    """Something the loop calls on every accepted step (statistics, averages, monitors).

    ``bind`` is called once before the first step (also on resume, before ``load_state_dict``),
    ``step(s0, s1)`` after every accepted step from s0 to s1, ``state_dict``/``load_state_dict`` carry
    its running state through checkpoints (a dict of numpy arrays), so a resumed run ends identical.
    """

    def bind(self, model: Model, system: System, state: State) -> None:
        pass

    def step(self, s0: State, s1: State) -> None:
        raise TypeError(f"{type(self).__name__} must define step(s0, s1)")

    def on_block(self, block) -> None:
        """Every accepted step of a compiled block (:class:`mbd.compiled.runner.Block`) in one call; by default
        :meth:`step` on each. An observer that overrides it reads the block's stacked states
        (``block.arrays()``) and skips building a State per step."""
        for s0, s1, _, _ in block.steps:
            self.step(s0, s1)

    def state_dict(self) -> dict:
        return {}

    def load_state_dict(self, d: dict) -> None:
        pass


@runtime_checkable
class Recorder(Protocol):
    """Samples the run and writes its results (implemented by ``mbd.Recorder``). The loop calls ``bind`` once,
    then ``reset`` and ``record(state, None, first=True)`` for a fresh run or ``restore`` on resume, ``record``
    after every accepted step of the numpy path and ``record_block`` for each block of the compiled one,
    ``checkpoint_state`` at a checkpoint (a JSON-able dict) and ``finalize`` at the end (the results path)."""

    def bind(self, model: Model, system: System, state: State) -> None: ...

    def reset(self) -> None: ...

    def record(self, s0: State, s1: State | None, first: bool = False) -> None: ...

    def record_block(self, block) -> None: ...

    def checkpoint_state(self) -> dict: ...

    def restore(self, st: dict) -> None: ...

    def finalize(self, attrs: dict | None = None) -> Path: ...


def _methods(protocol) -> list[str]:
    """The methods a protocol requires (its public functions, in the order written)."""
    return [k for k, v in vars(protocol).items() if inspect.isfunction(v) and not k.startswith("_")]


def require(protocol, obj, argument: str) -> None:
    """Raise ModelError, naming ``argument`` and the missing methods, unless ``obj`` has every method of
    ``protocol`` (structural: inheriting from it is not needed)."""
    missing = [m for m in _methods(protocol) if not callable(getattr(obj, m, None))]
    if missing:
        args = lambda m: ", ".join(p for p in inspect.signature(getattr(protocol, m)).parameters if p != "self")  # noqa: E731
        raise ModelError(f"simulate: {argument} ({type(obj).__name__}) is missing "
                         + ", ".join(f"{m}({args(m)})" for m in missing)
                         + f" of the {protocol.__name__} protocol (mbd.protocols.{protocol.__name__})")

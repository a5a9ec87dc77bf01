"""mbd: a generic planar rigid-body engine.

Static :class:`Model` built by a :class:`ModelBuilder`; mutable :class:`State`; vectorised element
families (:mod:`mbd.element`); sparse assembly (:class:`System`); HHT-α stepper with step controllers
and one :func:`simulate` loop; chunked atomic :class:`Recorder`; a scipy ``solve_ivp`` adapter;
linearization and modal analysis. It knows nothing about gears or bearings.
"""
from .assembly import Evaluation, System
from .control import Adaptive, FixedStep
from .element import Element, body_dofs, marker, marker_velocity, point_force
from .errors import IntegrationError, ModelError
from .hht import HHT, Tolerance, hht_coefficients
from .modal import linearize, modal_analysis
from .model import BodyRef, Frame, FrameState, Model, ModelBuilder, State, to_fixed, to_reference
from . import protocols
from .protocols import Controller, Observer
from .recorder import BodyMotion, DerivedOutput, ElementOutput, Recorder, atomic_write_bytes, atomic_write_text
from .scipy_adapter import FirstOrderSystem, solve_scipy
from .settings import PRODUCTION, IntegratorSettings
from .simulate import Checkpoint, Counters, SimResult, TimeMean, load_state, output_evaluator, save_state, simulate

__all__ = [
    "Adaptive", "BodyMotion", "BodyRef", "Checkpoint", "Controller", "Counters", "DerivedOutput", "Element", "ElementOutput", "Evaluation",
    "FirstOrderSystem", "FixedStep", "Frame", "FrameState", "HHT", "IntegratorSettings", "PRODUCTION", "IntegrationError", "Model",
    "ModelBuilder", "ModelError", "Observer", "Recorder", "SimResult", "State", "System", "TimeMean", "Tolerance",
    "atomic_write_bytes", "atomic_write_text", "body_dofs", "hht_coefficients", "protocols", "linearize", "load_state", "marker", "marker_velocity",
    "modal_analysis", "output_evaluator", "point_force", "save_state", "simulate", "solve_scipy", "to_fixed", "to_reference",
]

"""Tests of the engine (mbd): elements, compiled kernels, stepper, Newton, frames, recorder, static solver."""

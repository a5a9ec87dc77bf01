"""Tests of the domain (components): parameters, geometry, scenes, contact laws in the machine, outputs, statistics."""

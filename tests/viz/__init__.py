"""Tests of the plots, animations and results reading (viz)."""

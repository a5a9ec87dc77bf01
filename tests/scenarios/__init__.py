"""Tests of the studies and their machinery (scenarios): runner, sweeps, integrity, locks, each study end to end."""

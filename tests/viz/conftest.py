"""Fixtures of the viz tests."""
from __future__ import annotations

import pytest

from viz import render_check


@pytest.fixture(scope="module")
def offscreen():
    """The offscreen probe's message; the test skips with the probe's reason where this machine cannot render
    offscreen (one probe per test module)."""
    ok, msg = render_check.check_offscreen()
    if not ok:
        pytest.skip(msg)
    return msg

"""Can this machine render offscreen with VTK?  Find out without risking the caller.

VTK does not raise when no OpenGL context can be made offscreen: with neither a usable EGL nor an
OSMesa library it segfaults and takes the whole Python process with it.  So the probe here first looks
for the libraries, then renders a one-frame test plot in a *subprocess* for each candidate VTK window
class, and only reports success once one of them has produced a non-blank image.

VTK >= 9.4 wheels pick the window class at run time from ``VTK_DEFAULT_OPENGL_WINDOW``; once a class
is known to work, :func:`check_offscreen` exports it in this process so that later in-process renders
(viz.animate) use the same, proven path instead of trying X first.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import functools
import os
import signal
import subprocess
import sys
import threading

__all__ = ["check_offscreen", "check_offscreen_beside", "require_offscreen", "DEBIAN_PACKAGES"]

DEBIAN_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6"

_ENV = "VTK_DEFAULT_OPENGL_WINDOW"
_EGL = "vtkEGLRenderWindow"
_OSMESA = "vtkOSOpenGLRenderWindow"
_X = "vtkXOpenGLRenderWindow"

# The probe renders a small surface and prints the image statistics; anything else means failure.
_PROBE = r"""
import numpy as np, pyvista as pv
pv.OFF_SCREEN = True
p = pv.Plotter(off_screen=True, window_size=(64, 48))
p.set_background("white")
p.add_mesh(pv.Sphere(), color="black")
img = p.screenshot(return_img=True)
cls = type(p.ren_win).__name__
p.close()
print("PROBE", cls, img.shape[1], img.shape[0], float(np.asarray(img, float).std()))
"""


def _loadable(names: list[str]) -> str | None:
    """First of `names` that ctypes can actually load (find_library alone misses broken installs)."""
    for name in names:
        if name is None:
            continue
        try:
            ctypes.CDLL(name)
        except OSError:
            continue
        return name
    return None


def _find_libs() -> dict[str, str | None]:
    egl = _loadable(["libEGL.so.1", ctypes.util.find_library("EGL")])
    osmesa = _loadable(["libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so",
                        ctypes.util.find_library("OSMesa")])
    return {"EGL": egl, "OSMesa": osmesa}


def _probe(window_class: str | None, timeout: float) -> tuple[bool, str]:
    env = dict(os.environ)
    if window_class is not None:
        env[_ENV] = window_class
    try:
        res = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True,
                             text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"test render timed out after {timeout:g} s"
    if res.returncode < 0:
        try:
            sig = signal.Signals(-res.returncode).name
        except ValueError:
            sig = f"signal {-res.returncode}"
        return False, f"test render crashed ({sig})"
    lines = [ln for ln in res.stdout.splitlines() if ln.startswith("PROBE ")]
    if res.returncode != 0 or not lines:
        tail = (res.stderr.strip().splitlines() or ["no output"])[-1]
        return False, f"test render failed (exit {res.returncode}): {tail}"
    _, cls, w, h, std = lines[-1].split()
    if float(std) <= 1.0:
        return False, f"test render with {cls} produced a blank {w}x{h} image"
    return True, f"offscreen rendering works via {cls}"


@functools.lru_cache(maxsize=1)
def _check(timeout: float) -> tuple[bool, str, str | None]:
    """(ok, message, the window class proven here — None when the user chose it)."""
    libs = _find_libs()
    requested = os.environ.get(_ENV)
    if requested:
        candidates = [requested]  # the user chose; test only that
    else:
        candidates = []
        if libs["EGL"]:
            candidates.append(_EGL)
        if libs["OSMesa"]:
            candidates.append(_OSMESA)
        if os.environ.get("DISPLAY"):
            candidates.append(_X)
        if not candidates:
            return False, ("no offscreen OpenGL library found (neither libEGL.so.1 nor libOSMesa "
                           "can be loaded) and no X display; VTK would segfault. Install the Debian "
                           f"packages: apt-get install {DEBIAN_PACKAGES}"), None
    failures = []
    for cls in candidates:
        ok, msg = _probe(cls, timeout)
        if ok:
            found = ", ".join(f"{k}: {v}" for k, v in libs.items() if v) or "no GL libraries"
            return True, f"{msg} ({found})", (None if requested else cls)
        failures.append(f"{cls}: {msg}")
    return False, ("offscreen rendering is not usable (" + "; ".join(failures) + "). Install the "
                   f"Debian packages: apt-get install {DEBIAN_PACKAGES}"), None


_CHECKING = threading.Lock()     # one probe at a time: a second caller waits for the first one's cached answer


def _answer(timeout: float) -> tuple[bool, str, str | None]:
    with _CHECKING:
        return _check(float(timeout))


def check_offscreen(timeout: float = 60.0) -> tuple[bool, str]:
    """Return (ok, message).  Never crashes the caller; the result is cached for the process.  The window class
    that worked is exported here, in the caller's thread, for its later in-process renders."""
    ok, msg, proven = _answer(timeout)
    if proven is not None:
        os.environ[_ENV] = proven  # later in-process renders take the proven path
    return ok, msg


def check_offscreen_beside(timeout: float = 60.0) -> None:
    """Start the check in a thread and return at once: the probe's subprocess (≈ 1.4 s) runs while the caller
    imports and reads its data; the caller's own :func:`check_offscreen` then waits for its answer (and exports
    the window class: the thread leaves the environment alone while the caller imports)."""
    threading.Thread(target=_answer, args=(timeout,), name="dpgt-offscreen-check", daemon=True).start()


def require_offscreen() -> str:
    """Raise RuntimeError (naming the packages to install) unless offscreen rendering works."""
    ok, msg = check_offscreen()
    if not ok:
        raise RuntimeError(msg)
    return msg


if __name__ == "__main__":
    ok, msg = check_offscreen()
    print(("OK: " if ok else "FAIL: ") + msg)
    sys.exit(0 if ok else 1)

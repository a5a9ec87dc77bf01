"""Small engine scenes shared by test modules (built from mbd alone)."""
from __future__ import annotations

import mbd
from mbd.elements import BodySpring, GroundSupport, TorsionalSpring


def spinning_scene(frame, gravity=(0.0, 0.0), damping=True, fixed_body=False):
    """Two bodies joined by an offset BodySpring, body a on a ground support, body b spinning.
    With ``fixed_body`` a housing fixed in I holds body b through a second offset spring and an
    anisotropic support (defined in I) acts on body a."""
    c = 0.4 if damping else 0.0
    b = mbd.ModelBuilder(frame=frame, gravity=gravity)
    a = b.add_body("a", 1.2, 4e-3, pose=(0.05, 0.0, 0.0))
    bb = b.add_body("b", 0.4, 1e-3, pose=(0.15, 0.02, 0.0))
    b.add(BodySpring("link", a, bb, k=4e4, c=c, marker_a=(0.05, 0.0), marker_b=(-0.04, 0.01)))
    if fixed_body:
        h = b.add_body("housing", 5.0, 1.0, pose=(0.2, -0.1, 0.3), fixed=True)
        b.add(BodySpring("mount", h, bb, k=2e4, c=c, marker_a=(-0.03, 0.1), marker_b=(0.02, 0.0)))
        b.add(GroundSupport("sup", a, kx=6e4, ky=2e4, cx=c, cy=2 * c, anchor=(0.04, 0.01), k_theta=30.0))
    else:
        b.add(GroundSupport("sup", a, kx=6e4, cx=c, anchor=(0.04, 0.01), k_theta=30.0, c_theta=0.01 * c))
    b.add(TorsionalSpring("tors", a, bb, k=5.0, c=0.02 * c))
    return b.build()

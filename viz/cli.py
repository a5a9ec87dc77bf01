"""`dpgt animate`: animate a saved DPGT results file.

    dpgt animate RESULTS --out FILE [--kind cage|train] [--frame carrier|fixed] [--magnify X]
                 [--fps N] [--size WxH] [--max-frames N] [--compare OTHER_RESULTS] [--pair N]
                 [--no-rollers]

RESULTS is a results.nc or the run directory holding it; FILE ends in .gif or .mp4.
  --kind cage   cage-centre orbits of planet pair --pair (1..N, default 1: planets a1, b1; inner and outer PB)
                in the guide clearance;
                with --compare, the two runs side by side (forward and reverse);
                --magnify scales the schematic roller pocket offsets (default: automatic).
  --kind train  the whole train, rollers coloured by their inner-race load, seen from the carrier
                (--frame carrier) or from the housing (--frame fixed); --magnify scales displacements
                from the nominal positions (default 1: true scale).
Exit status: 0 written, 1 bad input file or no offscreen rendering, 2 bad arguments.

examples:
  dpgt animate results/demo/c3_forward --compare results/demo/c3_reverse --out cage_orbits.gif
  dpgt animate results/demo/c3_reverse/results.nc --kind train --frame fixed --max-frames 200 --out train.mp4

writes: the animation FILE given by --out (required: no default)
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from components.names import argparse_hint

from . import render_check
from .results import ResultsError, cage_panels, load_run, train_bodies

__all__ = ["main", "build_parser"]

PROG = "dpgt animate"
_DEFAULT_SIZE = {"cage": (800, 420), "cage-compare": (1600, 460), "train": (700, 640)}


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH in pixels, e.g. 800x400, got {text!r}") from None
    if w < 16 or h < 16:
        raise argparse.ArgumentTypeError(f"size {text!r} is too small (at least 16x16)")
    return w, h


def _positive(kind):
    def conv(text: str):
        try:
            x = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a {kind.__name__}, got {text!r}") from None
        if not x > 0:
            raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
        return x
    return conv


class _Parser(argparse.ArgumentParser):
    """argparse whose unknown options and invalid choices name the closest valid ones."""

    def error(self, message):
        super().error(argparse_hint(self, message))


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog=PROG, description="Animate saved DPGT results (offscreen).",
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=__doc__.split("\n\n", 2)[2] if __doc__ else None)
    p.add_argument("results", help="results.nc of a DPGT run, or its run directory")
    p.add_argument("--out", required=True, help="output animation, .gif or .mp4")
    p.add_argument("--kind", choices=("cage", "train"), default="cage",
                   help="cage orbits (default) or the whole train")
    p.add_argument("--frame", choices=("carrier", "fixed"), default="carrier",
                   help="train view: seen from the carrier (default) or the housing")
    p.add_argument("--magnify", type=_positive(float), default=None,
                   help="train: displacement factor (default 1); cage: roller offset factor (default auto)")
    p.add_argument("--fps", type=_positive(float), default=20.0, help="frames per second (default 20)")
    p.add_argument("--size", type=_size, default=None, help="WxH pixels (default depends on --kind)")
    p.add_argument("--max-frames", type=_positive(int), default=None,
                   help="at most this many frames, spread evenly over the run (default: every sample)")
    p.add_argument("--compare", default=None, metavar="OTHER_RESULTS",
                   help="cage: a second run (e.g. the reverse one) shown side by side")
    p.add_argument("--pair", type=_positive(int), default=1,
                   help="planet pair of the cage orbits, counted from 1 as the planets are named (pair n holds "
                        "a<n> and b<n>; default 1: the reference pair)")
    p.add_argument("--no-rollers", action="store_true", help="cage: leave out the roller offsets")
    return p


def _fail(msg: str, code: int = 1) -> int:
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    return code


def main(argv=None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
    except SystemExit as exc:  # argparse has printed its message (or the help)
        return int(exc.code or 0)
    out = Path(args.out)
    if out.suffix.lower() not in (".gif", ".mp4"):
        return _fail(f"--out must end in .gif or .mp4, got {out.name!r}", 2)
    if args.kind == "train" and args.compare:
        return _fail("--compare applies to --kind cage only", 2)
    for what, path in (("results", args.results), ("--compare", args.compare)):
        if path is not None and not Path(path).exists():      # a usage error, before anything loads
            return _fail(f"argument {what}: no such file or folder {path!r}", 2)

    # Inputs first (cheap, clear messages), then the offscreen probe, then VTK.
    try:
        run = load_run(args.results)
        other = load_run(args.compare) if args.compare else None
        if args.kind == "cage":
            if args.pair > len(run.pairs):
                return _fail(f"argument --pair: {args.pair} is not a planet pair of {args.results} "
                             f"(pairs 1..{len(run.pairs)})", 2)
            panels = cage_panels([run] + ([other] if other else []), pair=args.pair - 1,
                                 rollers=not args.no_rollers)
        else:
            bodies = train_bodies(run, frame=args.frame,
                                  magnify=1.0 if args.magnify is None else args.magnify)
    except ResultsError as exc:
        return _fail(str(exc))
    ok, msg = render_check.check_offscreen()
    if not ok:
        return _fail(f"cannot render offscreen: {msg}")

    from . import animate  # deferred: pyvista/VTK only when an animation is made
    try:
        if args.kind == "cage":
            size = args.size or _DEFAULT_SIZE["cage-compare" if other else "cage"]
            title = "Cage orbits in the guide clearance" + (
                f", planet pair {args.pair}" if args.pair != 1 else "")
            if other is None:
                title += f" ({run.direction})"
            path = animate.cage_orbit_animation(out, panels["t"], panels["orbits"], panels["clearance_m"],
                                                magnify=args.magnify, rollers=panels["rollers"],
                                                fps=args.fps, size=size, title=title,
                                                max_frames=args.max_frames)
            n_t = panels["t"].size
        else:
            size = args.size or _DEFAULT_SIZE["train"]
            view = "carrier" if args.frame == "carrier" else "housing"
            title = f"{run.direction}, seen from the {view}"
            if args.magnify not in (None, 1.0):
                title += f", displacements ×{args.magnify:g}"
            path = animate.train_animation(out, run.t, bodies, magnify=1.0, fps=args.fps, size=size,
                                           title=title, max_frames=args.max_frames,
                                           force_label="roller load\non the pin")
            n_t = run.n_t
    except (ValueError, RuntimeError) as exc:  # argument checks of viz.animate, renderer failures
        return _fail(str(exc))
    n = animate.frame_indices(n_t, args.max_frames).size
    print(f"wrote {path} ({n} frames, {size[0]}x{size[1]}, {args.fps:g} fps)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

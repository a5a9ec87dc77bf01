"""Architecture rules that keep the code honest: no import cycles between modules,
the engine never imports the domain, and no physics value hides in an element constructor's default."""
from __future__ import annotations

import ast
import dataclasses
import inspect
import re
import subprocess
from pathlib import Path

import pytest

import mbd.elements as elements
from mbd.element import Element
from mbd.elements.contact import TRACTION_LAWS

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("mbd", "components", "scenarios", "viz")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph() -> dict[str, set[str]]:
    """module -> project modules it imports (anywhere in the file, relative imports resolved)."""
    files = {_module_name(p): p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")}
    graph = {}
    for mod, path in files.items():
        package = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join([*up, base] if base else up)
                names = [base] + [f"{base}.{a.name}" for a in node.names]
            else:
                continue
            deps |= {n for n in names if n in files and n != mod}
        graph[mod] = deps
    return graph


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Import cycles between modules (depth-first search); a package's __init__ re-exporting its own
    modules is not counted."""
    state, cycles = {}, []

    def visit(m, stack):
        state[m] = 1
        for d in sorted(graph[m]):
            if state.get(d) == 1:
                cycles.append(stack[stack.index(d):] + [d])
            elif d not in state:
                visit(d, stack + [d])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    return [c for c in cycles if not any(a.startswith(b + ".") or b.startswith(a + ".") for a, b in zip(c, c[1:]))]


def test_no_import_cycles():
    assert find_cycles({"p.a": {"p.b"}, "p.b": {"p.c"}, "p.c": {"p.a"}}) == [["p.a", "p.b", "p.c", "p.a"]]
    cycles = find_cycles(import_graph())
    assert not cycles, f"import cycles: {cycles}"


def test_the_engine_knows_nothing_of_the_domain():
    graph = import_graph()
    for mod, deps in graph.items():
        if mod.startswith("mbd"):
            assert not [d for d in deps if not d.startswith("mbd")], (mod, deps)


# what viz reads results through: the results module's namespace, summary and reader
RESULTS = "components.results"
RESULTS_ENGINE_FREE = {RESULTS, f"{RESULTS}.summary", f"{RESULTS}.reader"}


def test_viz_reads_results_only_and_scenarios_build_without_viz():
    """viz draws from files (no engine, no parameters); the simulation side builds without viz (the
    scenarios that plot import it, the runner and the scene builders do not). The exceptions: the
    did-you-mean of every command (components.names), which imports nothing of the project, and the results
    module's reader (RESULTS_ENGINE_FREE), which imports nothing beyond itself."""
    graph = import_graph()
    assert graph["components.names"] == set()
    for mod, deps in graph.items():
        if mod.startswith("viz"):
            assert not [d for d in deps if d.split(".")[0] in ("mbd", "components", "scenarios")
                        and d not in {"components.names", *RESULTS_ENGINE_FREE}], (mod, deps)
        if mod.startswith(("components", "mbd")) or mod == "scenarios.core.runner":
            assert not [d for d in deps if d.startswith("viz")], (mod, deps)


# element constructor arguments that may have a default: structure, not physics
STRUCTURAL = {"multiplicity": 1, "ramp": None, "anchor": (0.0, 0.0), "marker_a": (0.0, 0.0),
              "marker_b": (0.0, 0.0), "theta0": 0.0, "u0": 0.0, "p0": 0.0, "phi_ref": 0.0}


def _element_classes():
    seen = set()
    for name in dir(elements):
        obj = getattr(elements, name)
        if inspect.isclass(obj) and issubclass(obj, Element) and obj is not Element and obj not in seen:
            seen.add(obj)
            yield obj


def test_no_physics_value_hides_in_an_element_constructor_default():
    """Every physical coefficient (friction, reference speeds, restitution, exponents, damping ratios,
    traction laws) comes from the parameter objects with its source tag. Defaults may only switch a term
    off (None or 0) or give structure (STRUCTURAL)."""
    classes = list(_element_classes())
    assert len(classes) >= 10
    bad = []
    for cls in classes:
        for p in inspect.signature(cls.__init__).parameters.values():
            d = p.default
            if d is inspect.Parameter.empty or d is None or p.name in ("self", "name"):
                continue
            if p.name in STRUCTURAL and d == STRUCTURAL[p.name]:
                continue
            if isinstance(d, (int, float)) and not isinstance(d, bool) and d == 0:
                continue          # a term switched off
            if isinstance(d, bool):
                continue
            bad.append(f"{cls.__name__}.{p.name}={d!r}")
    assert not bad, f"physics values as constructor defaults: {bad}"


def test_law_variants_are_registered_classes_without_default_coefficients():
    """Traction laws, impact laws and mesh-stiffness shapes: small dataclasses registered by name, every
    coefficient required (it comes from the parameters)."""
    from mbd.elements import IMPACT_LAWS, STIFFNESS_SHAPES
    for registry in (TRACTION_LAWS, IMPACT_LAWS, STIFFNESS_SHAPES):
        for name, law in registry.items():
            assert dataclasses.is_dataclass(law) and law.__dataclass_params__.frozen, name
            assert all(f.default is dataclasses.MISSING for f in dataclasses.fields(law)), name
    assert dataclasses.fields(TRACTION_LAWS["tanh"]) and dataclasses.fields(STIFFNESS_SHAPES["rectangular"])
    from mbd.elements.gear_mesh import StiffnessShape
    sig = inspect.signature(StiffnessShape.rectangular).parameters
    assert all(sig[k].default is inspect.Parameter.empty for k in ("contact_ratio", "ratio", "smoothing"))


def test_parameter_choices_name_the_registered_laws():
    """A law chosen by a parameter must exist in its registry, and every registered law is selectable."""
    from components.params import BearingParams, CageParams
    from mbd.elements import IMPACT_LAWS
    choices = lambda cls, name: set(cls._spec(name).choices)
    assert choices(CageParams, "impact_law") == set(IMPACT_LAWS)
    from mbd.elements import LAND_LAWS
    assert choices(CageParams, "land_law") == set(LAND_LAWS)
    assert choices(BearingParams, "traction_law") == set(TRACTION_LAWS)


def test_the_parameter_package_is_entered_through_components_params():
    """Parameters are used through ``components.params`` (its __init__ re-exports every public name); its modules,
    the machinery above all, are the package's own business."""
    graph = import_graph()
    assert {"components.params._machinery", "components.params.machine"} <= set(graph)
    inner = {(mod, d) for mod, deps in graph.items() if not mod.startswith("components.params")
             for d in deps if d.startswith("components.params.")}
    assert not inner, sorted(inner)


def test_every_si_class_is_written_out_next_to_its_parameter_class():
    """No SI class is made at run time (a type checker would not see it): each is a class statement in its
    parameter class's module, declaring every field (tests/components/test_params_typing.py runs mypy)."""
    import components.params as P

    def subclasses(cls):
        for sub in cls.__subclasses__():
            yield sub
            yield from subclasses(sub)

    for cls in [*subclasses(P.Params), P.DPGTOperatingSI, P.DPGTSupportSI]:
        si = cls.SI if issubclass(cls, P.Params) else cls
        src = inspect.getsource(si)
        assert si.__module__ == cls.__module__ and src.lstrip("@").split("\n")[1].startswith(f"class {si.__name__}(")
        own = si.__dict__["__annotations__"]
        assert own and all(re.search(rf"^    {n}: ", src, re.M) for n in own), si.__name__


def test_scene_handles_are_typed():
    """A DPGT's pairs and bearings are frozen dataclasses (attributes, not string keys)."""
    import dataclasses as dc
    import warnings

    from components.bearing import BearingHandles
    from components.dpgt import PairHandles, build_dpgt
    from components.presets import reference_dpgt
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(reference_dpgt(3, "forward"))
    pair = sc.pairs[0]
    assert isinstance(pair, PairHandles) and isinstance(pair.bearing("outer"), BearingHandles)
    with pytest.raises(dc.FrozenInstanceError):
        pair.inner = "x"
    b = pair.inner_bearing
    assert b.kind == "rollers" and len(b.rollers) == 12 and b.guide is not None and b.spring is None


def test_each_scene_builder_returns_a_frozen_typed_scene():
    """The DPGT, the bearing rig and the single planetary return frozen dataclasses derived from BuiltScene whose
    fields are declared (no ``meta``/``handles`` dict); the DPGT's run metadata is plain JSON and holds what
    viz.results reads back from results.nc (the carrier speed, direction, frame)."""
    import dataclasses as dc
    import json
    import warnings

    from components.dpgt import DPGTScene, build_dpgt
    from components.planetary import PlanetaryScene, build_single_planetary
    from components.presets import reference_dpgt
    from components.rig import BearingRigScene, build_bearing_rig
    from components.scene import BuiltScene

    p = reference_dpgt(3, "reverse")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        built = {DPGTScene: build_dpgt(p), BearingRigScene: build_bearing_rig(p.bearing, radial_load=5e3),
                 PlanetaryScene: build_single_planetary()}
    for cls, sc in built.items():
        assert type(sc) is cls and issubclass(cls, BuiltScene) and dc.is_dataclass(cls)
        names = {f.name for f in dc.fields(cls)}
        assert not names & {"meta", "handles"} and not hasattr(sc, "meta") and not hasattr(sc, "handles"), cls
        with pytest.raises(dc.FrozenInstanceError):
            sc.model = None
    run_meta = json.loads(json.dumps(built[DPGTScene].run_metadata()))       # no default=: plain JSON types only
    op = p.si().operating
    assert run_meta["speeds_rad_s"] == {"sun": op.sun_speed, "inner_planet": op.inner_planet_speed,
                                    "outer_planet": op.outer_planet_speed, "carrier": op.carrier_speed}
    assert tuple(run_meta[k] for k in ("direction", "frame", "planets", "rollers")) == ("reverse", "rotating", 3, 12)


# a string-keyed read or write of a scene's metadata or handles dict: by a literal key ([], get, setdefault, pop), update
_STRING_KEYED = re.compile(r"""\b(meta|handles)\s*(\[\s*["']|\.(get|setdefault|pop)\(\s*["']|\.update\()""")
# files that read results.nc's own "meta" attribute (a file format: JSON written from DPGTScene.run_metadata)
_RESULTS_FILE_META = {"viz/results.py", "tests/viz/test_viz_results.py"}


def test_no_string_keyed_scene_metadata_or_handles():
    """Scenes carry typed fields: no code reads ``meta[...]``/``handles[...]`` (or ``.get``/``.update`` them) by
    string, except where results.nc's own JSON ``meta`` attribute is read back."""
    hits = []
    for path in sorted([*(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")), *(ROOT / "tests").rglob("*.py")]):
        rel = path.relative_to(ROOT).as_posix()
        if rel in _RESULTS_FILE_META:
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if _STRING_KEYED.search(line) and "_STRING_KEYED" not in line:
                hits.append(f"{rel}:{n}: {line.strip()}")
    assert not hits, "string-keyed scene metadata or handles:\n" + "\n".join(hits)
    assert _STRING_KEYED.search('x = scene.meta["bearing"]') and _STRING_KEYED.search("h.handles.get('pairs', ())")


def test_scene_touches_no_private_attribute_of_the_model_builder():
    """components.scene works through ModelBuilder's public methods: no ``x._name`` on anything but its own self."""
    import mbd

    tree = ast.parse((ROOT / "components" / "scene.py").read_text(encoding="utf-8"))
    private = [f"line {node.lineno}: {ast.unparse(node)}" for node in ast.walk(tree)
               if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
               and not (isinstance(node.value, ast.Name) and node.value.id == "self")]
    assert not private, f"components/scene.py reaches into another object's private attributes: {private}"
    builder = set(vars(mbd.ModelBuilder(gravity=(0.0, 0.0))))
    assert {"_pose", "_mass", "_inertia"} <= builder        # what Scene used to write and read


# scenarios/ in three kinds: the studies a user runs at the top of the package, beside the two entrances
# (the console command, the Python entry point) and the shims that keep the numerics scripts' documented
# `python -m scenarios.NAME`; the numerics and benchmark scripts in scenarios.numerics; the machinery they share in
# scenarios.core. The kinds are read from the layout, so a new module is walled in by where it is put.
ENTRANCES = {"scenarios", "scenarios.cli", "scenarios.api"}


def scenario_kinds(graph: dict[str, set[str]]) -> dict[str, str]:
    """scenarios module -> "core", "numerics", "shim" (a top-level module named as a numerics script), "entrance" or
    "study"."""
    kinds = {}
    for mod in graph:
        parts = mod.split(".")
        if parts[0] != "scenarios":
            continue
        kinds[mod] = ("entrance" if mod in ENTRANCES else parts[1] if parts[1] in ("core", "numerics")
                      else "shim" if f"scenarios.numerics.{parts[1]}" in graph else "study")
    return kinds


# the modules every scenario builds on; a scenario borrows nothing from another scenario
def scenario_infrastructure(graph: dict[str, set[str]]) -> set[str]:
    return {"scenarios", "scenarios.numerics", "scenarios.numerics.common",
            *(m for m, k in scenario_kinds(graph).items() if k == "core")}


def test_no_scenario_borrows_from_another_scenario():
    """Shared helpers (--set parsing, scene switches, the reference HHT run, the housing sensor's signals) live in
    the infrastructure modules, not in the study that wrote them first; only the demo is another study (the paper
    study with its own defaults), and a shim is its numerics script's command."""
    graph = import_graph()
    infrastructure = scenario_infrastructure(graph)
    assert {"scenarios.core.args", "scenarios.core.runner", "scenarios.core.study"} <= infrastructure
    shims = {(m, m.replace("scenarios.", "scenarios.numerics.", 1))
             for m, k in scenario_kinds(graph).items() if k == "shim"}
    borrowed = {(mod, d) for mod, deps in graph.items() if mod.startswith("scenarios.")
                and mod not in infrastructure for d in deps
                if d.startswith("scenarios.") and d not in infrastructure}
    assert borrowed <= {("scenarios.demo", "scenarios.paper_study")} | shims, sorted(borrowed)


# what each kind may import of the project: a study the machinery (and viz to draw), never a numerics script; the
# machinery no command and no viz; a numerics script the machinery and its own package's common code, never a study;
# an entrance the machinery (the console command finds the commands by name at run time; the package re-exports the
# Python entry point); mbd and components nothing of scenarios. The packages scenarios and scenarios.numerics, which
# every import of their modules passes through, are no wall's business.
MAY_IMPORT = {"study": {"study", "core", "mbd", "components", "viz"}, "core": {"core", "mbd", "components"},
              "numerics": {"numerics", "core", "mbd", "components", "viz"}, "entrance": {"entrance", "core", "mbd", "components"},
              "mbd": {"mbd"}, "components": {"components", "mbd"}}


def walls_broken(graph: dict[str, set[str]]) -> list[str]:
    kinds = scenario_kinds(graph)
    kind_of = lambda mod: kinds.get(mod, mod.split(".")[0])
    bad = []
    for mod, deps in graph.items():
        kind = kind_of(mod)
        if kind == "shim":       # exactly its numerics script
            if deps != {mod.replace("scenarios.", "scenarios.numerics.", 1)}:
                bad.append(f"{mod} (a shim) imports {sorted(deps)}")
            continue
        if kind in MAY_IMPORT:
            bad += [f"{mod} ({kind}) imports {d} ({kind_of(d)})" for d in sorted(deps)
                    if kind_of(d) not in MAY_IMPORT[kind] and d not in ("scenarios", "scenarios.numerics")]
    return bad


def test_scenarios_show_their_three_kinds_and_the_walls_between_them():
    """The layout holds the studies at the top, the numerics scripts in scenarios.numerics and the shared machinery in
    scenarios.core, and each kind imports only what MAY_IMPORT lets it (the walls are shown first to catch a study
    importing a numerics script, the machinery importing a study, a numerics script a study, components the
    machinery and a shim more than its script)."""
    graph = import_graph()
    kinds = scenario_kinds(graph)
    by_kind = {k: sorted(m for m, kk in kinds.items() if kk == k) for k in ("study", "core", "numerics", "shim")}
    assert {"scenarios.paper_study", "scenarios.demo", "scenarios.spectrum", "scenarios.params"} <= set(by_kind["study"])
    assert {f"scenarios.core.{m}" for m in ("args", "command", "lock", "sweep", "runner", "study", "integrity",
                                            "plausibility", "analysis")} <= set(by_kind["core"])
    assert {f"scenarios.numerics.{m}" for m in ("benchmark", "bench_engine", "work_precision", "stability", "warm",
                                                "common")} <= set(by_kind["numerics"])
    assert not [m for m in by_kind["study"] + by_kind["core"] + by_kind["numerics"] if m.count(".") > 2]
    broken = {"scenarios.paper_study": {"scenarios.numerics.common"}, "scenarios.core.sweep": {"scenarios.spectrum"},
              "scenarios.numerics.stability": {"scenarios.fault_study"}, "components.outputs": {"scenarios.core.args"},
              "scenarios.warm": {"scenarios.numerics.warm", "scenarios.core.args"}}
    assert len(walls_broken({**graph, **{m: graph[m] | d for m, d in broken.items()}})) == len(broken)
    assert not walls_broken(graph), "\n".join(walls_broken(graph))


def test_every_numerics_script_has_its_command_and_every_shim_is_one_import():
    """A numerics script with a ``main`` is run as ``python -m scenarios.NAME`` through a shim of that name, which
    holds no code of its own (no second copy): its docstring, ``from .numerics.NAME import main`` and the
    ``__main__`` guard."""
    graph = import_graph()
    kinds = scenario_kinds(graph)
    scripts = {m.rsplit(".", 1)[1] for m, k in kinds.items() if k == "numerics" and m != "scenarios.numerics"
               and "def main(" in (ROOT / (m.replace(".", "/") + ".py")).read_text(encoding="utf-8")}
    shims = {m.rsplit(".", 1)[1] for m, k in kinds.items() if k == "shim"}
    assert len(scripts) >= 9 and scripts == shims, (scripts ^ shims)
    for name in shims:
        body = ast.parse((ROOT / "scenarios" / f"{name}.py").read_text(encoding="utf-8")).body
        assert isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant), name      # docstring
        assert [ast.unparse(n) for n in body[1:]] == [
            f"from .numerics.{name} import main", "if __name__ == '__main__':\n    raise SystemExit(main())"], name


# a function-local import says why it is not at the top of its module: it breaks an import cycle
# ("# cycle: ..."), or it defers a heavy or optional import that a start-up path does not need ("# deferred: ...":
# numba's kernels, VTK, Dask, matplotlib, xarray/HDF5, the runner in dpgt's start-up). The reason is on the import's
# line, or on a comment line right above the block of imports it belongs to.
LOCAL_IMPORT_REASON = re.compile(r"#\s*(?:deferred|cycle):\s*\S")
_IMPORT_LINE = re.compile(r"\s*(?:from\s+\S+\s+import\s|import\s)")


def local_imports_without_reason(source: str) -> list[str]:
    """The function-local imports of a module's source that give no reason (their lines)."""
    lines = source.splitlines()

    def reasoned(lineno: int) -> bool:
        if LOCAL_IMPORT_REASON.search(lines[lineno - 1]):
            return True
        above = lineno - 2
        while above >= 0 and _IMPORT_LINE.match(lines[above]):          # the block of imports it belongs to
            above -= 1
        return above >= 0 and lines[above].lstrip().startswith("#") and bool(LOCAL_IMPORT_REASON.search(lines[above]))

    bad = []

    def visit(node, in_function: bool):
        for child in ast.iter_child_nodes(node):
            if in_function and isinstance(child, (ast.Import, ast.ImportFrom)) and not reasoned(child.lineno):
                bad.append(lines[child.lineno - 1].strip())
            visit(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))

    visit(ast.parse(source), False)
    return bad


def test_every_function_local_import_says_why_it_is_not_at_the_top():
    """A module's imports are at its top; one inside a function carries its reason (LOCAL_IMPORT_REASON), so a new
    one must say why. Shown first on a module written to break it: an untagged import inside a function (and in a
    method) is caught; a tagged one, a tagged block and the module's own top-level and TYPE_CHECKING imports pass."""
    probe = ("import os\nif TYPE_CHECKING:\n    import numpy\n"
             "def f():\n    import json\n    from math import pi  # deferred: a reason\n"
             "    # cycle: a.b imports this module\n    from a import b\n    from a import c\n    x = 1\n    import re\n"
             "class C:\n    def g(self):\n        from pathlib import Path\n")
    assert local_imports_without_reason(probe) == ["import json", "import re", "from pathlib import Path"]
    bad = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            found = local_imports_without_reason(path.read_text(encoding="utf-8"))
            if found:
                bad[str(path.relative_to(ROOT))] = found
    assert not bad, "function-local imports without a '# deferred:' or '# cycle:' reason: " + "; ".join(
        f"{f}: {', '.join(v)}" for f, v in bad.items())


# what a clone does not have: the specification files the project was started from, which lived beside the
# repository, and paths of the machine it was written on (patterns split so that this file does not match itself)
OUTSIDE = re.compile("|".join([re.escape("shared" + "/spec"), re.escape("../" + "shared"), re.escape("/" + "work/"),
                               r"\b(?:MODEL|PARAMETERS|ARCHITECTURE)" + r"\.md\b"]))


def tracked_text_files() -> list[Path]:
    """The repository's tracked files (git ls-files; the source packages, docs and tests when git is absent),
    text only."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
        files = [ROOT / f for f in out.decode().split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        files = [p for d in (*PACKAGES, "tests", "docs") for p in (ROOT / d).rglob("*") if p.is_file()]
        files += [ROOT / "README.md", ROOT / "Makefile", ROOT / "pyproject.toml"]
    return [f for f in files if f.is_file() and b"\0" not in f.read_bytes()[:8192]]


def test_no_tracked_file_cites_a_file_outside_the_repository():
    """The model and the parameters are the project's own documents (docs/model.md §N, docs/parameters.md); a
    citation of the specification files beside the repository, or of a path on one machine, points nowhere in a
    clone."""
    assert OUTSIDE.search("see " + "MODEL" + ".md §3.2") and OUTSIDE.search("../" + "shared" + "/spec/x")
    assert not OUTSIDE.search("docs/model.md §6.2, docs/parameters.md")
    files = tracked_text_files()
    assert any(f.name == "model.md" for f in files) and any(f.suffix == ".py" for f in files)
    bad = [f"{f.relative_to(ROOT)}:{n}: {line.strip()[:80]}" for f in files
           for n, line in enumerate(f.read_text(encoding="utf-8", errors="replace").splitlines(), 1)
           if OUTSIDE.search(line)]
    assert not bad, "citations of files outside the repository:\n" + "\n".join(bad)


# ------------------------------------------------------------------------------------------ compiled twins
def _dispatch_branches(function: str) -> dict[str, str]:
    """kind constant -> the kernel its branch of mbd.compiled.registry.<function> calls ("module.function"),
    read from the if-chain's source (numba compiles that chain; nothing else dispatches)."""
    tree = ast.parse((ROOT / "mbd" / "compiled" / "registry.py").read_text(encoding="utf-8"))
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == function)
    out = {}
    for node in ast.walk(fn):
        if isinstance(node, ast.If) and isinstance(node.test, ast.Compare) and isinstance(node.test.ops[0], ast.Eq):
            const = node.test.comparators[0].id
            call = node.body[0].value
            assert isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute), (function, const)
            assert const not in out, f"{function}: two branches for {const}"
            out[const] = f"{call.func.value.id}.{call.func.attr}"
    return out


def _families() -> list[type]:
    """Every element family class of mbd.elements, the private bases included."""
    seen, todo = [], [Element]
    while todo:
        for sub in todo.pop().__subclasses__():
            if sub.__module__.startswith("mbd.elements") and sub not in seen:
                seen.append(sub)
                todo.append(sub)
    return seen


def test_every_declared_compiled_twin_has_its_kernels_and_dispatch_branches():
    """Each family declares its compiled twin ("module.name") where it is defined; the registry gives each twin
    an id whose branch of evaluate_kind calls module.evaluate_name, and of update_kind module.update_name
    exactly when the family has internal state; pack_name exists. No kernel is left without a family."""
    from mbd.compiled import registry
    evaluate, update = _dispatch_branches("evaluate_kind"), _dispatch_branches("update_kind")
    ids = {getattr(registry, c): c for c in evaluate}
    assert len(ids) == len(evaluate) == len(registry.KIND_IDS) == len(set(registry.KIND_IDS.values()))
    declared = {}
    for cls in _families():
        twin = cls.compiled_twin
        if twin is None:
            continue
        assert twin in registry.KIND_IDS, f"{cls.__name__}.compiled_twin = {twin!r} is not in registry.KIND_IDS"
        assert twin not in declared, f"{twin!r} declared by {declared[twin].__name__} and {cls.__name__}"
        declared[twin] = cls
        module, name = twin.split(".")
        const = ids[registry.KIND_IDS[twin]]
        assert evaluate[const] == f"{module}.evaluate_{name}", (twin, const, evaluate[const])
        kind = registry.kind_of(cls)
        assert callable(kind.pack) and kind.pack.__name__ == f"pack_{name}", twin
        stateful = cls.update_internal is not Element.update_internal
        assert (kind.update is not None) == stateful == (const in update), twin
        if stateful:
            assert update[const] == f"{module}.update_{name}", (twin, update[const])
    assert set(declared) == set(registry.KIND_IDS), f"kernels without a family: {set(registry.KIND_IDS) - set(declared)}"


def test_each_compiled_output_kernel_is_dispatched():
    """A twin that gives its family's outputs (registry.OUTPUT_NAMES, the names of the rows it writes) has
    module.outputs_name, and the branch of outputs_kind for its id calls that; no branch without an entry."""
    from mbd.compiled import registry
    branches = _dispatch_branches("outputs_kind")
    ids = {getattr(registry, c): c for c in branches}
    assert len(ids) == len(branches) == len(registry.OUTPUT_NAMES)
    for twin, names in registry.OUTPUT_NAMES.items():
        module, name = twin.split(".")
        const = ids[registry.KIND_IDS[twin]]
        assert branches[const] == f"{module}.outputs_{name}", (twin, branches[const])
        assert names and len(set(names)) == len(names), twin


def test_a_twin_is_declared_by_each_family_and_a_typo_fails_loudly():
    """A subclass does not inherit its parent's twin (its law may differ); an unknown twin is a LookupError
    naming the family, not a silent fall back to the numpy path."""
    from mbd.compiled.registry import kind_of
    from mbd.elements import RaceContact

    class Sub(RaceContact):
        pass

    class Typo(RaceContact):
        compiled_twin = "contact.raec"

    assert RaceContact.compiled_twin == "contact.race" and Sub.compiled_twin is None and kind_of(Sub) is None
    with pytest.raises(LookupError, match=r"Typo.compiled_twin = 'contact.raec'"):
        kind_of(Typo)


def _shipped_scenes():
    """(label, builder) of every scene the studies and scenarios build: the DPGT at each condition and
    direction, with every combination of the scene switches (--option), every fault of the fault study,
    the gear-quality study's flank classes, every selectable contact law, the stability study's cases; the
    bearing rig with each cage, with and without drag, at rest and turning; the single planetary (modal)."""
    import itertools
    import warnings

    from components.dpgt import build_dpgt
    from components.params import BearingParams, CageParams, with_overrides
    from components.planetary import build_single_planetary
    from components.presets import CONDITIONS, DIRECTIONS, reference_dpgt
    from components.rig import build_bearing_rig
    from components.scene import SceneOptions
    from scenarios.fault_study import FAULTS
    from scenarios.numerics.stability import CASES, case_overrides

    def dpgt(overrides=None, options=None, condition=3, direction="forward", strict=True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # design warnings of the stability study's variants
            return build_dpgt(with_overrides(reference_dpgt(condition, direction), overrides or {}), options, strict)

    for c, d in itertools.product(CONDITIONS, DIRECTIONS):
        yield f"DPGT condition {c} {d}", lambda c=c, d=d: dpgt(condition=c, direction=d)
    ch = SceneOptions._CHOICES
    for b, cage, drag, mesh, frame in itertools.product(ch["bearings"], ("free", "none"), (True, False),
                                                        ch["mesh_stiffness"], ch["frame"]):
        o = SceneOptions(bearings=b, cage=cage, drag=drag, mesh_stiffness=mesh, frame=frame)
        yield f"DPGT {o.given()}", lambda o=o: dpgt(options=o)
    for name, (ov, _) in FAULTS.items():
        yield f"fault study: {name}", lambda ov=ov: dpgt(ov)
    for grade in (5, 6, 8):
        ov = {"errors.flank_class": [{"gear": "all", "grade": grade, "seed": 1, "systematic_share": 0.5}]}
        yield f"gear quality: grade {grade}", lambda ov=ov: dpgt(ov)
    for key, cls, field in (("bearing.traction_law", BearingParams, "traction_law"),
                            ("bearing.cage.impact_law", CageParams, "impact_law"),
                            ("bearing.cage.land_law", CageParams, "land_law"),
                            ("bearing.cage.pocket_law", CageParams, "pocket_law")):
        for law in cls._spec(field).choices:
            yield f"{key} = {law}", lambda ov={key: law}: dpgt(ov)
    for name in CASES:
        yield f"stability: {name}", lambda name=name: dpgt(case_overrides(name)[0], strict=False)
    p = reference_dpgt()
    for cage, drag, speed in itertools.product(("held", "free", "none"), (True, False), (0.0, 300.0)):
        yield (f"bearing rig: cage {cage}, drag {drag}, {speed} rad/s",
               lambda cage=cage, drag=drag, speed=speed: build_bearing_rig(
                   p.bearing, radial_load=5e3, outer_speed=speed, lubricant=p.lubricant if drag else None,
                   options=SceneOptions(cage=cage, drag=drag, gravity=False)))
    yield "single planetary", build_single_planetary


def test_every_family_of_the_shipped_scenes_has_a_compiled_twin():
    """A family without a compiled twin sends a whole run to the ≈ 13× slower numpy path: every family of every
    shipped scene declares one, and the compiled system of each scene builds (its law variants pack)."""
    import mbd
    from mbd.compiled.registry import kind_of
    from mbd.compiled.system import CompiledSystem

    missing, refused, n = {}, [], 0          # family class -> the scenes it is in
    for label, build in _shipped_scenes():
        model = build().model
        n += 1
        for e in model.elements:
            if kind_of(type(e)) is None:
                missing.setdefault(type(e).__name__, []).append(label)
        try:
            CompiledSystem(mbd.System(model))
        except NotImplementedError as exc:
            refused.append(f"{label}: {exc}")
    assert n > 80
    assert not missing, "families without a compiled twin: " + "; ".join(
        f"{cls} (in {len(s)} scenes, e.g. {s[0]})" for cls, s in missing.items())
    assert not refused, f"{len(refused)} scenes the compiled path cannot build, e.g. {refused[:3]}"


# ------------------------------------------------------------------------------------------ one results module


def test_the_results_module_imports_no_engine_internals_and_viz_reads_through_it():
    """components.results: its namespace, the summary and the reader import nothing of the project
    (viz reads through them without the engine); its writer and schema take the engine only through ``mbd``'s
    public API (never ``mbd.<module>``); viz enters the project through components.results alone (and the
    did-you-mean, components.names)."""
    graph = import_graph()
    assert RESULTS_ENGINE_FREE | {f"{RESULTS}.io", f"{RESULTS}.schema"} <= set(graph)
    for mod in RESULTS_ENGINE_FREE:
        assert graph[mod] <= RESULTS_ENGINE_FREE, (mod, graph[mod])
    for mod, deps in graph.items():
        if mod.startswith(RESULTS):
            assert not [d for d in deps if d.startswith("mbd.")], (mod, deps)
        if mod.startswith("viz"):
            assert {d for d in deps if d.split(".")[0] == "components"} <= {"components.names", *RESULTS_ENGINE_FREE}, \
                (mod, deps)


def _calls(tree) -> list[tuple[str, ast.Call]]:
    """(dotted name of the callee, call) of every call in a module ("json.load", "xr.open_dataset", "File")."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f, parts = node.func, []
            while isinstance(f, ast.Attribute):
                parts.append(f.attr)
                f = f.value
            if isinstance(f, ast.Name):
                parts.append(f.id)
            out.append((".".join(reversed(parts)), node))
    return out


# the engine writes results.nc (its Recorder: a generic file of probes), the results module reads it
OPENS_RESULTS = {"mbd.recorder"}
# what opens a netCDF4/HDF5 file, by its module's name (however the module or the function was imported)
OPENERS = {"xarray.open_dataset", "xarray.load_dataset", "xarray.open_mfdataset", "h5py.File", "h5netcdf.File",
           "netCDF4.Dataset"}
RUN_FILES = ("summary.json", "results.nc", "SUMMARY_NAME", "RESULTS_NAME")


def _imported_as(tree) -> dict[str, str]:
    """{local name: dotted name it stands for} of every import in a module ("xr" -> "xarray", "File" -> "h5py.File")."""
    out = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update({a.asname or a.name: a.name for a in node.names})
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            out.update({a.asname or a.name: f"{node.module}.{a.name}" for a in node.names})
    return out


def _results_reads(mod: str, tree) -> dict[str, list[str]]:
    """What a module (not the results module) does that only components.results may: open a netCDF4/HDF5 file,
    read a summary or a run file by its name, ask a summary for its "error" (``Summary.failed``/``.error`` own the
    failed-run form), take the atomic writes from mbd.recorder."""
    found = {"opened": [], "summaries": [], "run files": [], "error key": [], "writes": []}
    alias = _imported_as(tree)
    for name, call in _calls(tree):
        head, _, rest = name.partition(".")
        full = ".".join(x for x in (alias.get(head, head), rest) if x)
        last = name.rsplit(".", 1)[-1]
        text = ast.unparse(call)
        if (last in ("open_dataset", "load_dataset", "open_mfdataset") and name != "open_dataset"
                or name in ("h5py.File", "h5netcdf.File") or full in OPENERS) and mod not in OPENS_RESULTS:
            found["opened"].append(f"{mod}: {name}")
        if name in ("json.load", "json.loads") and "summary" in text.lower():
            found["summaries"].append(f"{mod}: {text}")
        if (last in ("read_text", "read_bytes", "open", "load") or name == "open") and any(f in text for f in RUN_FILES):
            found["run files"].append(f"{mod}: {text}")
        if last == "get" and call.args and isinstance(call.args[0], ast.Constant) and call.args[0].value == "error":
            found["error key"].append(f"{mod}: {text}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare) and isinstance(node.left, ast.Constant) and node.left.value == "error" \
                and any(isinstance(op, (ast.In, ast.NotIn)) for op in node.ops):
            found["error key"].append(f"{mod}: {ast.unparse(node)}")
        if not mod.startswith("mbd") and isinstance(node, ast.ImportFrom) and node.module == "mbd.recorder" \
                and any(a.name.startswith("atomic_write") for a in node.names):
            found["writes"].append(mod)
    return found


def test_results_files_are_opened_only_in_the_results_module():
    """results.nc and summary.json are opened for reading only in components.results: no other module calls
    xarray's open_dataset/load_dataset or h5py/h5netcdf's File (under whatever name it was imported), reads a file
    it names summary.json or results.nc, or json.load(s) a summary (an argument that names one); no module asks a
    summary for "error" (Summary.failed); the atomic writes come from components.results.io (mbd keeps its own).
    The detector is shown first to find each of these in a module written to break them."""
    bad = ast.parse("import json\nfrom xarray import open_dataset as od\nimport h5py as h\n"
                    "from mbd.recorder import atomic_write_text\n"
                    "def f(p, s):\n    od(p)\n    h.File(p)\n    json.loads((p / 'summary.json').read_text())\n"
                    "    open(p / 'results.nc', 'rb')\n    return 'error' in s or s.get('error')\n")
    caught = _results_reads("scenarios.bad", bad)
    assert {k: len(v) for k, v in caught.items()} == {"opened": 2, "summaries": 1, "run files": 2, "error key": 2,
                                                      "writes": 1}, caught
    found: dict[str, list[str]] = {}
    for pkg in PACKAGES:
        for path in (ROOT / pkg).rglob("*.py"):
            mod = _module_name(path)
            if mod.startswith(RESULTS):
                continue
            for k, v in _results_reads(mod, ast.parse(path.read_text(encoding="utf-8"))).items():
                found.setdefault(k, []).extend(v)
    assert not found["opened"], f"results files opened outside components.results: {found['opened']}"
    assert not found["summaries"], f"summaries read outside components.results: {found['summaries']}"
    assert not found["run files"], f"run files read by name outside components.results: {found['run files']}"
    assert not found["error key"], f"a summary's error asked by its key, not Summary.failed: {found['error key']}"
    assert not found["writes"], f"atomic writes taken from mbd.recorder, not components.results.io: {found['writes']}"


# ------------------------------------------------------------------------------------------ the tests' layout
# the test modules that check what crosses the packages (the layout, the documents, the commands of every study,
# the output files' names, the tour notebook); every other test module lives in the folder of the package it tests
CROSS_CUTTING_TESTS = {"test_architecture.py", "test_commands.py", "test_docs.py", "test_summary_keys.py",
                       "test_tour_notebook.py"}


def _test_layout_problems(files: dict[str, str]) -> list[str]:
    """What breaks the tests' layout in ``files`` (path under tests/ -> source): a test module at the top that is
    not cross-cutting, a folder that is not a package's (or tests/support) or has no __init__.py, a test module in
    tests/support, an import of another test module or of a shared helper other than as tests.support.*, a change
    to sys.path."""
    problems = []
    folders = {p.split("/")[0] for p in files if "/" in p}
    local = {p.rsplit("/", 1)[-1].removesuffix(".py") for p in files}      # names a sys.path hack would import
    for folder in sorted(folders):
        if folder not in (*PACKAGES, "support"):
            problems.append(f"tests/{folder}/: not the folder of a package ({', '.join(PACKAGES)}) or support")
        if f"{folder}/__init__.py" not in files:
            problems.append(f"tests/{folder}/: no __init__.py (test modules are imported as tests.{folder}.NAME)")
    for path, source in sorted(files.items()):
        name = path.rsplit("/", 1)[-1]
        if "/" not in path and name.startswith("test_") and name not in CROSS_CUTTING_TESTS:
            problems.append(f"tests/{path}: a test module at the top (it belongs in the folder of its package)")
        if path.startswith("support/") and name.startswith("test_"):
            problems.append(f"tests/{path}: a test module among the shared helpers")
        for node in ast.walk(ast.parse(source)):
            mods = ([a.name for a in node.names] if isinstance(node, ast.Import)
                    else [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            for m in mods:
                parts = m.split(".")
                if (parts[0] == "tests" and parts[1:2] != ["support"] and len(parts) > 1) or parts[0] in local \
                        or any(p.startswith("test_") for p in parts):
                    problems.append(f"tests/{path}:{node.lineno}: imports {m} (shared helpers: tests.support.*)")
            if isinstance(node, ast.Attribute) and node.attr == "path" and isinstance(node.value, ast.Name) \
                    and node.value.id == "sys":
                problems.append(f"tests/{path}:{node.lineno}: changes or reads sys.path (import as tests.support.*)")
    return problems


def test_tests_mirror_the_packages_and_share_only_through_tests_support():
    """Test modules live in tests/mbd, tests/components, tests/scenarios and tests/viz, the cross-cutting ones at
    the top; every folder is a package, so a test module is imported by its dotted name wherever pytest runs from;
    what tests share lives in tests/support and is imported as tests.support.* — never from another test module,
    never through a sys.path entry. The detector is shown first to find each of these in a tree written to break
    them."""
    bad = {"__init__.py": "", "test_new_thing.py": "", "support/__init__.py": "", "support/test_helper.py": "",
           "mbd/__init__.py": "", "extra/test_x.py": "",
           "mbd/test_a.py": "import sys\nsys.path.insert(0, 'tests')\nfrom strategies import networks\n"
                            "from tests.mbd.test_b import helper\nimport test_c\nfrom tests.support.mesh import rb\n",
           "strategies.py": ""}
    caught = _test_layout_problems(bad)
    for words in ("test_new_thing.py: a test module at the top", "tests/extra/: not the folder",
                  "tests/extra/: no __init__.py", "support/test_helper.py: a test module among",
                  "imports strategies", "imports tests.mbd.test_b", "imports test_c", "mbd/test_a.py:2: changes"):
        assert any(words in c for c in caught), (words, caught)
    assert len(caught) == 8 and not any("tests.support.mesh" in c for c in caught), caught
    tests = ROOT / "tests"
    files = {p.relative_to(tests).as_posix(): p.read_text(encoding="utf-8") for p in tests.rglob("*.py")}
    assert {"__init__.py", "support/__init__.py", "support/strategies.py", "support/dpgt_runs.py"} <= set(files)
    assert {p.split("/")[0] for p in files if "/" in p} == {*PACKAGES, "support"}
    assert CROSS_CUTTING_TESTS <= set(files), CROSS_CUTTING_TESTS - set(files)
    problems = _test_layout_problems(files)
    assert not problems, "the tests' layout:\n" + "\n".join(problems)

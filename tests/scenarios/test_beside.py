"""Work beside the runs (scenarios.core.sweep.Beside): each group's task starts once, when its last case is in."""
from scenarios.core.sweep import Beside, Case, Outcome, Status


def _case(cond, d):
    return Case(cond, d, f"/nowhere/c{cond}_{d}")


def _done(case, ok=True):
    return Outcome(case, Status.FINISHED if ok else Status.FAILED, summary={"condition": case.condition} if ok else None)


def test_a_group_starts_once_and_only_when_all_its_cases_are_in():
    cases = [_case(c, d) for c in (1, 2) for d in ("forward", "reverse")]
    seen = []
    b = Beside(key=lambda c: c.condition, task=lambda k, outs: (seen.append((k, sorted(outs))) or len, (outs,)))
    groups, started, results = b.groups(cases), set(), {}
    assert list(b.ready(groups, results, started)) == []
    results[cases[0].label] = _done(cases[0])                 # condition 1 forward only: nothing starts
    results[cases[2].label] = _done(cases[2])                 # condition 2 forward
    assert list(b.ready(groups, results, started)) == []
    results[cases[1].label] = _done(cases[1])                 # condition 1 complete
    ready = list(b.ready(groups, results, started))
    assert [k for k, _ in ready] == [1] and seen == [(1, ["c1_forward", "c1_reverse"])]
    assert list(b.ready(groups, results, started)) == []      # never twice
    results[cases[3].label] = _done(cases[3])
    assert [k for k, _ in b.ready(groups, results, started)] == [2]
    for k, work in ready:
        b.here(k, work)
    assert b.done == {1: 2}                                   # len of the group's two outcomes


def test_cases_outside_every_group_wait_for_nothing_and_a_failing_task_is_kept_as_its_error():
    cases = [_case(3, "forward"), _case(4, "forward")]
    b = Beside(key=lambda c: c.condition if c.condition == 3 else None, task=lambda k, outs: (int, ("x",)))
    groups, started = b.groups(cases), set()
    assert groups == {3: ["c3_forward"]}
    (k, work), = b.ready(groups, {"c3_forward": _done(cases[0])}, started)
    b.here(k, work)
    assert isinstance(b.done[3], ValueError)


def test_the_paper_study_draws_a_point_beside_only_when_both_its_runs_finished(tmp_path):
    from scenarios import paper_study
    a = paper_study.parse_args(["--conditions", "2,3", "--out", str(tmp_path)])
    study = paper_study.PaperStudy(a)
    b = study.beside(study.config())
    f, r = _case(3, "forward"), _case(3, "reverse")
    assert b.task(3, {f.label: _done(f), r.label: _done(r, ok=False)}) is None
    pieces = b.task(3, {f.label: _done(f), r.label: _done(r)})
    assert all(fn is paper_study.point_work and fargs[2] == 3 for fn, fargs in pieces)
    assert [fargs[3] for _, fargs in pieces] == list(paper_study.POINT_PIECES)      # each on a worker of its own
    assert sorted(f for piece in paper_study.POINT_PIECES for f in piece) == sorted([*paper_study.HISTORY_GROUPS, "cage_orbits"])
    static = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", "--mode", "static",
                                                            "--out", str(tmp_path)]))
    assert static.beside(static.config()) is None
    one = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", "--out", str(tmp_path)]))
    assert one.beside(one.config()) is None     # one point (the demo): nothing runs beside its figures


def test_a_group_in_pieces_starts_each_piece_once_and_joins_their_lists_in_order():
    """A group's work in pieces (a list of (function, args)): every piece starts when the group is in, once; their
    lists are joined in the order of the pieces, whatever order they finish in; a piece that raises is the group's
    result (the report redraws that point)."""
    cases = [_case(1, "forward"), _case(1, "reverse")]
    b = Beside(key=lambda c: c.condition, task=lambda k, outs: [(list, ("ab",)), (list, ("cd",))])
    groups, started = b.groups(cases), set()
    results = {c.label: _done(c) for c in cases}
    ready = list(b.ready(groups, results, started))
    assert [k for k, _ in ready] == [1, 1] and list(b.ready(groups, results, started)) == []
    for k, work in ready:
        b.here(k, work)
    assert b.done == {1: ["a", "b", "c", "d"]} and len(b.spans) == 2
    bad = Beside(key=lambda c: c.condition, task=lambda k, outs: [(list, ("ab",)), (int, ("x",)), (list, ("cd",))])
    for k, work in bad.ready(bad.groups(cases), results, set()):
        bad.here(k, work)
    assert isinstance(bad.done[1], ValueError)

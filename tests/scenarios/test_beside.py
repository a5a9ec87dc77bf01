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
    fn, fargs = b.task(3, {f.label: _done(f), r.label: _done(r)})
    assert fn is paper_study.point_work and fargs[2] == 3
    static = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", "--mode", "static",
                                                            "--out", str(tmp_path)]))
    assert static.beside(static.config()) is None
    one = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", "--out", str(tmp_path)]))
    assert one.beside(one.config()) is None     # one point (the demo): nothing runs beside its figures

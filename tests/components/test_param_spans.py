"""The range an assumed value carries (``assumed(value, note, span=Span(low, high, basis, log))``): converted like
the value and checked where it is declared, kept while the value is the assumed one, gone once a user changes it."""
from __future__ import annotations

import pytest

from components.params import Span, SupportParams, assumed, spans, with_overrides
from components.presets import reference_dpgt
from components.units import ParameterError, to_si


def _support(**sun):
    return SupportParams(sun_stiffness=assumed("1e8 N/m", **sun), ring_stiffness="1e8 N/m",
                         carrier_stiffness="1e8 N/m", damping_ratio=0.02, ring_tangential_stiffness="1e9 N/m")


def test_a_range_is_converted_in_its_own_units_and_kept_with_the_assumed_value():
    s = _support(span=Span("1e3 N/mm", "1e10 N/m", "floating to rigid", log=True))
    span = s.source("sun_stiffness").span
    assert (to_si(span.low), to_si(span.high), span.log, span.basis) == (1e6, 1e10, True, "floating to rigid")
    assert spans(s) == {"sun_stiffness": span}
    assert spans(s.replace(damping_ratio=0.03)) == {"sun_stiffness": span}     # another value changed: kept
    assert spans(s.replace(sun_stiffness="2e8 N/m")) == {}                      # the user's value has no range


@pytest.mark.parametrize("span,words", [
    (Span("1e9 N/m", "1e7 N/m", "x"), "support.sun_stiffness: empty range: low '1e9 N/m' must be below high"),
    (Span("1e8 N/m", "1e8 N/m", "x"), "empty range"),
    (Span("1 kg", "2 kg", "x"), "support.sun_stiffness (range low): expected a stiffness"),
    (Span("-1 N/m", "1e9 N/m", "x"), "support.sun_stiffness (range low): must be >= 0"),
    (Span("0 N/m", "1e9 N/m", "x", log=True), "a log range needs low > 0"),
    (Span("1e9 N/m", "1e10 N/m", "x"), "the value 100000000.0 newton / meter lies outside its range"),
    (Span("1e6 N/m", "1e10 N/m", " "), "a range needs its basis"),
    (("1e6 N/m", "1e10 N/m"), "a range must be a Span(low, high, basis)"),
])
def test_a_bad_range_is_refused_where_it_is_declared_in_one_line(span, words):
    with pytest.raises(ParameterError) as e:
        _support(span=span)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_a_range_on_a_choice_is_refused():
    with pytest.raises(ParameterError, match="a range needs a quantity; this parameter is a choice"):
        with_overrides(reference_dpgt(3), {"bearing.cage.land_law": assumed("dry", span=Span("dry", "wet", "x"))})


def test_the_reference_machine_ranges_every_assumed_value_the_headline_outputs_may_rest_on():
    """Each range holds its assumed value (checked at construction), says why, and is one of an assumed value; the
    mesh stiffness, which ISO 6336-1 derives, has none."""
    p = reference_dpgt(3)
    got = spans(p)
    assert not {"mesh.c_gamma_alpha", "mesh.stiffness_ratio"} & set(got)
    assert {"support.sun_stiffness", "support.carrier_stiffness", "support.ring_stiffness", "mesh.damping_ratio",
            "mesh.damping_ramp", "bearing.clearance", "bearing.contact_damping_ratio",
            "bearing.cage.pocket_clearance", "bearing.cage.guide_clearance", "bearing.cage.guide_stiffness",
            "lubricant.drag_coefficient", "lubricant.temperature"} <= set(got)
    for key, span in got.items():
        *owner, name = key.split(".")
        obj = p
        for o in owner:
            obj = getattr(obj, o)
        assert obj.source(name).tag == "assumed" and span.basis.strip(), key
    assert got["support.sun_stiffness"].log and not got["bearing.clearance"].log
    assert to_si(got["lubricant.temperature"].low) == pytest.approx(313.15)   # 40 degC

"""Checks of a harness aircraft's entry shared by the per-aircraft tests (``test_jsbsim_<name>.py``): its names
(:func:`assert_names_resolve`), its checked-in model (:func:`checked_in_model`, :func:`assert_openflightsim_assembly`,
:func:`assert_openflightsim_direct_surfaces`), the glide derivation against the checked-in or stock model
(:func:`assert_kept_but_engines`, :func:`assert_same_aero_as_stock`) and the summaries' labels
(:func:`assert_summaries_label_bare`).

Twenty-eighth session: folded from sixteen per-aircraft files' copies with every assertion and tolerance kept;
twenty-ninth: moved here unchanged from ``truth_fits.py``. The FCS checks it calls are in ``static_checks.py``.
"""

from static_checks import assert_aero_is_the_only_force, assert_aileron_maps_back, surface_state

__all__ = ["assert_names_resolve", "same_xml", "assert_kept_but_engines", "bare_xml", "checked_in_model",
           "assert_openflightsim_assembly", "assert_openflightsim_direct_surfaces", "assert_same_aero_as_stock",
           "ROSTER_ORDER", "assert_summaries_label_bare"]


def assert_names_resolve(name: str, model: str, typo: str) -> None:
    """The harness name ``name`` and the JSBSim model name ``model`` resolve to ``name`` in any case
    and with spaces (``canonical_name``); the unknown ``typo`` raises a KeyError listing ``name``.

    Raises:
        AssertionError: one of these fails.
    """
    import re

    import pytest

    from benchmarks.jsbsim_harness import canonical_name

    assert canonical_name(model) == canonical_name(f" {name.upper()} ") == canonical_name(name) == name
    with pytest.raises(KeyError, match=f"unknown aircraft '{re.escape(typo)}' .*{re.escape(name)}"):
        canonical_name(typo)


def same_xml(a, b) -> bool:
    """Whether two XML elements are equal: their tag, attributes, text and children, not their own tails (the
    derivation tests of the checked-in models: the ka350's, s23's, dr1's)."""
    import copy
    import xml.etree.ElementTree as ET

    a, b = map(copy.deepcopy, (a, b))
    a.tail = b.tail = None
    return ET.tostring(a) == ET.tostring(b)


def assert_kept_but_engines(src, der, tags, n_engines: int, n_tanks: int) -> None:
    """The derived model ``der`` keeps the checked-in ``src``'s elements ``tags`` (:func:`same_xml`; ``src`` indented
    as the derived XML first, ``ET.indent(src, space=" ")``) and its ``n_tanks`` fuel tanks one for one, and has none
    of ``src``'s ``n_engines`` ``<propulsion><engine>`` (the glide derivations' checks: the fokker50's, navion's,
    dr1's, s23's and ka350's).

    Raises:
        AssertionError: an element, an engine count or a tank differs. ValueError: the two have another number of
            tanks (``zip(strict=True)``)."""
    for tag in tags:
        assert same_xml(src.find(tag), der.find(tag)), tag
    assert len(src.findall("propulsion/engine")) == n_engines and der.find("propulsion/engine") is None
    tanks = list(zip(src.findall("propulsion/tank"), der.findall("propulsion/tank"), strict=True))
    assert len(tanks) == n_tanks and all(same_xml(a, b) for a, b in tanks), len(tanks)


def bare_xml(e) -> bytes:
    """The element's XML with every text and tail stripped of white space: its content, not its layout (to compare
    a function of a checked-in file with the derived model's, whose indentation ``ET.indent`` rewrote)."""
    import copy
    import xml.etree.ElementTree as ET

    e = copy.deepcopy(e)
    for x in e.iter():
        x.text = x.text.strip() if x.text else x.text
        x.tail = None
    return ET.tostring(e)


def checked_in_model(name: str, model: str, src: str, n_bytes: int, sha256: str):
    """The checked-in XML ``src`` (a path from the repository root) of the harness aircraft ``name`` is the copy its
    README describes (``n_bytes`` long, SHA-256 ``sha256``), the aircraft flies it as the derived ``model``, and the
    spec's notes name the derived XML's digest.

    Returns:
        ``(source_root, derived_root, spec)``: the parsed source and derived XML (``ElementTree`` elements) and the
        :class:`~benchmarks.jsbsim_harness.AircraftSpec`.

    Raises:
        AssertionError: one of these fails.
    """
    import hashlib
    import xml.etree.ElementTree as ET

    from benchmarks.jsbsim_harness import aircraft
    from benchmarks.jsbsim_harness.derived import REPO_DERIVED, derived_sha, derived_xml
    from benchmarks.jsbsim_harness.logfile import _REPO

    raw = (_REPO / src).read_bytes()
    assert len(raw) == n_bytes and hashlib.sha256(raw).hexdigest() == sha256
    spec = aircraft(name)
    assert spec.model == model and REPO_DERIVED[spec.model][0] == src
    assert f"XML sha256 {derived_sha(spec.model)}" in spec.notes
    return ET.fromstring(raw), ET.fromstring(derived_xml(spec.model)), spec


def assert_openflightsim_assembly(name: str, folder: str, files: dict, parts: tuple, reads: dict) -> None:
    """The checked-in files of a UASLab/OpenFlightSim model (the ultrastick's, the us25e's) are the ones its README
    lists, and its derived model assembles them changing no number (``derived._openflightsim_glide``).

    Args:
        name: the harness aircraft.
        folder: the checked-in folder, from the repository root.
        files: file name -> (bytes, SHA-256), the main file first (the README's table).
        parts: ``(tag, file)`` of the metrics, mass and gear files and, last, ``("aerodynamics", file)``.
        reads: the aerodynamics' ``<property>`` reads renamed by the derivation -> how many there are
            (``fcs/posElev_rad`` -> ``fcs/elevator-pos-rad``, ``fcs/posRud_rad`` -> ``fcs/rudder-pos-rad``).

    Raises:
        AssertionError: a file differs from the README, the derived model has another layout (the fileheader,
            the three parts, an empty propulsion, the direct FCS, the aerodynamics; no system), a part differs
            from its file, or the aerodynamics differ from the file but for the renamed reads.
    """
    import hashlib
    import xml.etree.ElementTree as ET

    from benchmarks.jsbsim_harness import aircraft
    from benchmarks.jsbsim_harness.derived import REPO_DERIVED, derived_sha, derived_xml
    from benchmarks.jsbsim_harness.logfile import _REPO

    for f, (n, sha) in files.items():
        raw = (_REPO / folder / f).read_bytes()
        assert len(raw) == n and hashlib.sha256(raw).hexdigest() == sha, f
    spec = aircraft(name)
    assert REPO_DERIVED[spec.model][0] == f"{folder}/{next(iter(files))}"
    assert f"XML sha256 {derived_sha(spec.model)}" in spec.notes
    der = ET.fromstring(derived_xml(spec.model))
    canon = lambda e: "".join(ET.tostring(e, encoding="unicode").split())   # noqa: E731  (layout aside: ET.indent)
    assert [c.tag for c in der] == ["fileheader", "metrics", "mass_balance", "ground_reactions", "propulsion",
                                    "flight_control", "aerodynamics"]
    for tag, f in parts[:-1]:
        assert canon(der.find(tag)) == canon(ET.parse(_REPO / folder / f).getroot()), tag
    assert list(der.find("propulsion")) == [] and der.find("system") is None
    aero = ET.parse(_REPO / folder / parts[-1][1]).getroot()
    got = [p.text for p in aero.iter("property")]
    assert {k: got.count(k) for k in reads} == reads
    rename = {"fcs/posElev_rad": "fcs/elevator-pos-rad", "fcs/posRud_rad": "fcs/rudder-pos-rad"}
    for p in aero.iter("property"):
        p.text = rename.get(p.text, p.text)
    assert canon(aero) == canon(der.find("aerodynamics"))


def assert_openflightsim_direct_surfaces(name: str, surface_rad: float, min_lift_lbs: float) -> None:
    """A UASLab/OpenFlightSim derived model (the ultrastick's, the us25e's) maps each command straight to its surface,
    +-``surface_rad`` (``aerosurface_scale``, no actuator dynamics, no damper): elevator -> ``fcs/elevator-pos-rad``,
    rudder -> ``fcs/rudder-pos-rad``, aileron -> ``fcs/posAilL_rad`` and ``fcs/posAilR_rad`` = -left (the harness reads
    both, delta_a = -0.5 (left - right) = -left); the flaps stay 0; a yaw rate does not move the rudder. No engine;
    after 50 frames every non-gravity force and moment is aerodynamic, at least ``min_lift_lbs`` of lift.

    Raises:
        AssertionError: the first check that fails.
    """
    from benchmarks.jsbsim_harness import aircraft

    spec = aircraft(name)
    assert not spec.gear_up and spec.aileron_props == ("fcs/posAilL_rad", "fcs/posAilR_rad")
    fdm = surface_state(spec, {"fcs/elevator-pos-rad": (0, surface_rad), "fcs/posAilL_rad": (1, surface_rad),
                               "fcs/posAilR_rad": (1, -surface_rad), "fcs/rudder-pos-rad": (2, surface_rad)},
                        alpha_deg=2.0, r_rad_s=0.2)
    assert fdm.get_propulsion().get_num_engines() == 0
    assert fdm["fcs/posFlapL_rad"] == 0.0 and fdm["fcs/posFlapR_rad"] == 0.0
    assert_aileron_maps_back(spec, 2.0)
    assert_aero_is_the_only_force(fdm, min_lift_lbs, external_zero=True)


def assert_same_aero_as_stock(state, stock_state, n_engines: int, zero=()) -> None:
    """At three states (alpha 4, -3, 0 deg; sideslip 4, -2, 0 deg; the commands (0.3, -0.4, 0.2), (-0.2, 0.3, -0.5),
    0), JSBSim's aerodynamic forces and moments of a derived model (``state(alpha, beta, cmds)``, no engine) equal
    those of the wheel's stock model (``stock_state``, its ``n_engines`` engines stopped) to the last bit (the
    navion's, s23's and dr1's derivation checks: the derivation changes no number). The properties ``zero`` read 0
    in both.

    Raises:
        AssertionError: an engine count, a ``zero`` property or a force or moment differs."""
    for alpha, beta, cmds in ((4.0, 4.0, (0.3, -0.4, 0.2)), (-3.0, -2.0, (-0.2, 0.3, -0.5)), (0.0, 0.0, (0, 0, 0))):
        a, b = state(alpha, beta, cmds), stock_state(alpha, beta, cmds)
        assert a.get_propulsion().get_num_engines() == 0 and b.get_propulsion().get_num_engines() == n_engines
        for k in zero:
            assert a[k] == b[k] == 0.0, (alpha, k)
        for k in ("forces/fbx-aero-lbs", "forces/fby-aero-lbs", "forces/fbz-aero-lbs", "moments/l-aero-lbsft",
                  "moments/m-aero-lbsft", "moments/n-aero-lbsft"):
            assert a[k] == b[k], (alpha, k)


#: The roster in the order the aircraft were added, the fokker50 last (the summaries' label tests take prefixes).
ROSTER_ORDER = ("c172x", "pa28", "j3cub", "c182", "t37", "t6", "b747", "f16", "f4n", "rascal", "sgs126", "asw20",
                "iar80", "c684", "ultrastick", "b737", "c172p", "eternity", "us25e", "ka350", "s23", "dr1", "navion",
                "fokker50")


def assert_summaries_label_bare(tmp_path, last: str, clean: tuple[str, ...]) -> None:
    """The markdown summaries of ``eval_jsbsim`` and ``eval_jsbsim_diagnose`` label every aircraft of
    :data:`ROSTER_ORDER` up to ``last`` bare (synthetic rows of those aircraft alone): no row reads
    "(untouched)" or "(held out)", every aircraft has its ``| NAME | light`` row in the first, and each of ``clean``
    its ``| NAME | clean |`` row in the second.

    Args:
        tmp_path: a folder for the two synthetic .jsonl files.
        last: the last aircraft of the roster's prefix written.
        clean: the aircraft whose clean rows the diagnosis summary must show.

    Raises:
        AssertionError: a label or row differs.
    """
    import json

    from benchmarks import eval_jsbsim, eval_jsbsim_diagnose
    from gcs_sysid.aero.table import COEFFICIENTS

    def row(ac):
        errs = {k: {c: 10.0 for c in COEFFICIENTS} for k in ("meas", "gp", "true", "ls")}
        return {"aircraft": ac, "turbulence": "light", "aoa": "ahrs", "seed": 1, **errs, "cov_gp": 90.0,
                "cov_true": 90.0, "alpha_deg": 0.1, "beta_deg": 0.1, "alpha_rms_deg": 1.0, "beta_rms_deg": 1.0}

    acs = ROSTER_ORDER[:ROSTER_ORDER.index(last) + 1]
    p = tmp_path / "r.jsonl"
    p.write_text("".join(json.dumps(row(ac)) + "\n" for ac in acs))
    lines = eval_jsbsim.summarize([str(p)]).splitlines()
    for ac in acs:
        assert any(ln.startswith(f"| {ac} | light") for ln in lines), ac
    assert not any("(held out)" in ln or "(untouched)" in ln for ln in lines)
    d = tmp_path / "d.jsonl"
    d.write_text("".join(json.dumps({"aircraft": ac, "seed": 11, "effects": [], "score": {"ok": True}}) + "\n"
                         for ac in acs))
    lines = eval_jsbsim_diagnose.summarize([str(d)]).splitlines()
    for ac in clean:
        assert any(ln.startswith(f"| {ac} | clean |") for ln in lines), ac
    assert not any("(untouched)" in ln for ln in lines)

"""The harness's derived JSBSim models written into an aircraft folder (``install_derived_models``), also when another
process (a second test worker on a fresh installation) puts the same model in place between the check and the rename:
that is no failure and no warning (the fresh-clone CI of the seventieth session warned "the harness cannot fly it"
while the model was in place)."""

import shutil
import warnings

from benchmarks.jsbsim_harness import derived

NAMES = list(derived.DERIVED) + list(derived.REPO_DERIVED)


def _base(tmp_path):
    """An aircraft folder holding the stock models the derived ones are made from."""
    for stock in {v[0] for v in derived.DERIVED.values()}:
        shutil.copytree(derived._wheel_root() / "aircraft" / stock, tmp_path / stock)
    return tmp_path


def _want(base):
    return {n: derived.derived_xml(n, base / derived.DERIVED[n][0] if n in derived.DERIVED else None) for n in NAMES}


def test_models_written_then_left_alone_then_a_stale_one_replaced(tmp_path):
    base = _base(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert {p.name for p in derived.install_derived_models(base)} == set(NAMES)
        assert derived.install_derived_models(base) == []            # up to date: nothing written again
        stale = base / "Rascal110_glide" / "Rascal110_glide.xml"
        stale.write_bytes(b"<old/>")
        assert [p.name for p in derived.install_derived_models(base)] == ["Rascal110_glide"]
    assert stale.read_bytes() == _want(base)["Rascal110_glide"]
    assert not [p for p in base.iterdir() if p.name.startswith(".")]   # no temporary or old folder left


def test_a_concurrent_writer_that_got_there_first_is_no_failure(tmp_path, monkeypatch):
    base = _base(tmp_path)
    want = _want(base)
    real_rename = derived.Path.rename

    def rename(self, target):
        target = derived.Path(target)
        if target.parent == base and target.name in want:       # the final placement: theirs lands just before it
            target.mkdir(exist_ok=True)
            (target / f"{target.name}.xml").write_bytes(want[target.name])
            (target / "marker").write_text("theirs")
        return real_rename(self, target)                       # fails: the folder is there and not empty

    monkeypatch.setattr(derived.Path, "rename", rename)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                          # before the fix: "could not write the derived ..."
        derived.install_derived_models(base)
    for name, xml in want.items():
        assert (base / name / f"{name}.xml").read_bytes() == xml and (base / name / "marker").read_text() == "theirs"
    assert not [p for p in base.iterdir() if p.name.startswith(".")]

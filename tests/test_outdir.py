"""Staged outputs (gcs_sysid.outdir): whole or not at all, nothing stale, refusals before any work."""

import json
import os
import subprocess
import sys

import pytest

from gcs_sysid.errors import InputError
from gcs_sysid.outdir import MARKER, StagedDir, StagedFiles, check_out_dir, check_out_file


def _tree(p):
    return {str(f.relative_to(p)): f.read_bytes() for f in sorted(p.rglob("*")) if f.is_file()}


def _earlier(out):
    out.mkdir()
    (out / "report.html").write_text("old report")
    (out / "model.npz").write_bytes(b"old model")
    (out / MARKER).write_text("{}")
    return _tree(out)


def _partials(parent):
    return [p.name for p in parent.iterdir() if ".partial-" in p.name]


def test_commit_replaces_everything(tmp_path):
    out = tmp_path / "o"
    _earlier(out)
    with StagedDir(out, "replay") as st:
        assert st.path.parent == tmp_path and st.path != out
        (st.path / "report.html").write_text("new report")
        assert (out / "report.html").read_text() == "old report"   # untouched until the end
    assert (out / "report.html").read_text() == "new report"
    assert not (out / "model.npz").exists()                       # nothing stale survives
    assert json.loads((out / MARKER).read_text())["command"] == "replay"
    assert _partials(tmp_path) == []
    mask = os.umask(0o022)
    os.umask(mask)
    assert out.stat().st_mode & 0o777 == 0o777 & ~mask   # not the private mode of a temporary folder


def test_failure_leaves_earlier_outputs(tmp_path):
    out = tmp_path / "o"
    before = _earlier(out)
    with pytest.raises(RuntimeError):
        with StagedDir(out, "replay") as st:
            (st.path / "report.html").write_text("half")
            raise RuntimeError("boom")
    assert _tree(out) == before
    assert _partials(tmp_path) == []


def test_new_folder_and_parents(tmp_path):
    out = tmp_path / "a" / "b" / "o"
    with StagedDir(out, "diagnose") as st:
        (st.path / "diagnosis.json").write_text("{}")
    assert sorted(os.listdir(out)) == sorted([MARKER, "diagnosis.json"])


def test_refusals(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(InputError, match="--out .*file: is an existing file"):
        check_out_dir(f)
    with pytest.raises(InputError, match="is a file, not a folder"):
        check_out_dir(f / "sub")
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "thesis.tex").write_text("precious")
    with pytest.raises(InputError, match="holds files gcs-sysid did not write \\(thesis.tex\\)"):
        StagedDir(foreign, "replay", owned=("report.html",))
    assert (foreign / "thesis.tex").read_text() == "precious" and _partials(tmp_path) == []
    older = tmp_path / "older"    # an output of a version before the marker: only known names
    older.mkdir()
    (older / "report.html").write_text("old")
    check_out_dir(older, owned=("report.html",))
    with pytest.raises(InputError, match="is a folder"):
        check_out_file(tmp_path)


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_unwritable_parent(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(InputError, match="cannot write in"):
            check_out_dir(ro / "o")
    finally:
        ro.chmod(0o700)


def test_stale_partial_of_a_dead_process_is_removed(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    stale = tmp_path / f".o.partial-{dead}-abc"
    stale.mkdir()
    (stale / "report.html").write_text("half")
    with StagedDir(tmp_path / "o", "replay") as st:
        (st.path / "x").write_text("1")
    assert not stale.exists() and _partials(tmp_path) == []


def test_staged_files(tmp_path):
    a, b = tmp_path / "m.toml", tmp_path / "m.fit.json"
    a.write_text("old")
    with pytest.raises(ValueError):
        with StagedFiles(a, b) as st:
            st.path(a).write_text("new")
            raise ValueError
    assert a.read_text() == "old" and not b.exists() and _partials(tmp_path) == []
    with StagedFiles(a, b) as st:
        assert st.path(a).suffix == ".toml"
        st.path(a).write_text("new")
        st.path(b).write_text("{}")
    assert a.read_text() == "new" and b.read_text() == "{}" and _partials(tmp_path) == []

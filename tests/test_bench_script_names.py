"""Every name a benchmark script's functions read is defined somewhere (the module, an import, a builtin).

The JSBSim evaluation scripts import most of the package inside their functions (so that ``--help`` and
``--summary`` stay light), which no test run reaches without flying or loading flights: ``clean_scatter``
(``eval_jsbsim_diagnose --scatter``) read ``air_roll_for`` without importing it from d2d5a2f until the
thirty-second session (``docs/benchmarks.md``, *Thirty-second session, i9-csp32*). This reads each script's
symbol table (:mod:`symtable`, nothing imported or run): a name that a function reads as a global but that the
module never binds and Python does not provide fails.
"""

import builtins
import symtable
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SCRIPTS = ("benchmarks/eval_jsbsim_diagnose.py", "benchmarks/eval_jsbsim.py", "benchmarks/issue8_counts.py",
           "benchmarks/beta_profile_diag.py", "benchmarks/pool_eval.py", "benchmarks/scale_sideslip_truth.py",
           "benchmarks/term_shares.py", "benchmarks/effect_bias_split.py", "benchmarks/sideslip_truth_screen.py")


def unbound_globals(source: str, filename: str) -> list[str]:
    """``"function: name"`` for each name a function (at any depth) reads as a global that the module does not
    bind and that is not a builtin. Args: the module's source text and its name (for messages)."""
    top = symtable.symtable(source, filename, "exec")
    bound = {s.get_name() for s in top.get_symbols() if s.is_assigned() or s.is_imported()}
    bound |= set(dir(builtins)) | {"__file__", "__name__", "__doc__"}
    out = []

    def walk(t):
        for c in t.get_children():
            if c.get_type() == "function":
                for s in c.get_symbols():
                    if s.is_referenced() and s.is_global() and s.get_name() not in bound:
                        out.append(f"{c.get_name()}: {s.get_name()}")
            walk(c)

    walk(top)
    return sorted(set(out))


@pytest.mark.parametrize("script", SCRIPTS)
def test_benchmark_script_reads_no_unbound_name(script):
    path = REPO / script
    assert unbound_globals(path.read_text(), str(path)) == []


def test_the_check_finds_a_missing_import():
    src = "def f():\n    from os import sep\n    return sep + missing_name\n"
    assert unbound_globals(src, "x.py") == ["f: missing_name"]

"""``benchmarks/pool_eval.py``'s arms: a worker runs many jobs and the evaluation scripts set module-level switches
from their options, so every arm must name the same options, or a switch one arm set leaks into the next arm's job.
(The pool's runs themselves fly JSBSim and take minutes; they are measured in docs/benchmarks.md, fortieth session.)"""

import pytest

from benchmarks.pool_eval import EFFECT_GROUPS, parse_arms


def test_arms_that_name_the_same_options_parse():
    arms = parse_arms(["base:--wind-residual-scale off", "ws: --wind-residual-scale on"])
    assert arms == [("base", ["--wind-residual-scale", "off"]), ("ws", ["--wind-residual-scale", "on"])]
    assert parse_arms(["a:", "b:"]) == [("a", []), ("b", [])]
    assert [n for n, _ in parse_arms(["a:--x=on", "b:--x off"])] == ["a", "b"]       # --opt=value names --opt
    assert parse_arms(["x:--sparse-thresholds '{\"a\": 1}'"]) == [("x", ["--sparse-thresholds", '{"a": 1}'])]


@pytest.mark.parametrize("specs, words", [
    (["base:", "ws:--wind-residual-scale on"], "same options"),       # the switch would leak into base's next job
    (["base:--wind-window 15", "ws:--wind-residual-scale on"], "same options"),
    (["--wind-residual-scale on"], "NAME:OPTIONS"),
    (["a:--x 1", "a:--x 2"], "twice"),
])
def test_arms_that_would_leak_a_switch_are_refused(specs, words):
    with pytest.raises(ValueError, match=words):
        parse_arms(specs)


def test_a_clean_only_arm_must_be_an_arm(capsys):
    from benchmarks.pool_eval import main

    with pytest.raises(SystemExit):
        main(["issue9", "--seed", "3", "--arm", "a:", "--clean-only-arms", "b", "--work", "W", "--out", "O"])
    assert "--clean-only-arms b: no such --arm" in capsys.readouterr().err


def test_the_effect_groups_cover_issue_9s_six_effects_once():
    from benchmarks.eval_jsbsim_diagnose import EFFECTS

    names = [e for g in EFFECT_GROUPS for e in g]
    assert sorted(names) == sorted(EFFECTS) and len(set(names)) == len(names)

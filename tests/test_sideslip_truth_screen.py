"""benchmarks/sideslip_truth_screen.py: the band gain and the summary (the flights' part needs harness flights and is
run by hand; docs/benchmarks.md, "Sixty-second session, lead")."""

import numpy as np

from benchmarks.sideslip_truth_screen import BANDS, band_gains, summary


def test_band_gain_reads_a_scale_and_ignores_independent_noise():
    rng = np.random.default_rng(0)
    t = np.arange(0, 600, 0.02)
    x = np.convolve(rng.standard_normal(len(t)), np.ones(25) / 25, mode="same")     # band-limited, about 0-2 Hz
    y = 0.8 * x + 0.3 * np.std(x) * rng.standard_normal(len(t))
    g = band_gains(t, x, y)
    assert len(g) == len(BANDS)
    assert np.allclose(g, 0.8, atol=0.06)
    y[::7] = np.nan                                  # rows with a NaN are dropped, not propagated
    assert np.isfinite(band_gains(t, x, y)).all()


def _line(flight, est, err, gain):
    return {"flight": flight, "estimator": est, "error": err, "gains": [1.0, gain, gain, 1.0, 1.0]}


def test_summary_compares_with_the_first_estimator():
    lines = [_line("a", "ls", 0.30, 0.8), _line("a", "gls", 0.15, 1.0),
             _line("b", "ls", 0.10, 0.9), _line("b", "gls", 0.12, 1.1),
             _line("c", "ls", 0.20, 0.7)]                       # c has one estimator only: left out
    out = summary(lines)
    assert out[0] == "| flight | error ls | error gls | gain ls | gain gls |"
    assert [o.split(" |")[0] for o in out[2:4]] == ["| a", "| b"] and len(out) == 6
    assert out[4].startswith("ls: error median 0.200, mean 0.200;")
    assert out[5].endswith("against ls: better 1, worse 1")

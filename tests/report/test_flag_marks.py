"""The envelope figures' flagged-cell marks (gcs_sysid.report.plots._flag_marks) draw what matplotlib's contour sets
drew before them (``contourf(levels=[0.5, 1.5], hatches=["///"])`` and ``contour(levels=[0.5])``), pixel for pixel,
on flag grids with holes, corners, islands, a whole grid flagged and one cell flagged."""

import io

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from gcs_sysid.report.plots import _flag_marks


def _pixels(draw) -> np.ndarray:
    fig = Figure(figsize=(2.0, 2.0))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.imshow(np.linspace(0, 1, 24 * 20).reshape(20, 24), extent=(-1, 1, 0, 3), origin="lower", aspect="auto",
              interpolation="nearest")
    ax.plot(np.linspace(-1, 1, 50), np.linspace(0, 3, 50), ".", ms=1)
    draw(ax)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=96)
    return np.asarray(Image.open(buf).convert("RGB"))


def _contour_sets(ax, xc, yc, flag):
    """What plots.envelope_figures drew before (the 58th session's code)."""
    if flag.any() and not flag.all():
        ax.contourf(xc, yc, flag, levels=[0.5, 1.5], colors="none", hatches=["///"])
        ax.contour(xc, yc, flag, levels=[0.5], colors="#00bcd4", linewidths=1.0)
    elif flag.all():
        ax.contourf(xc, yc, flag + np.linspace(0, 1e-6, flag.size).reshape(flag.shape), levels=[0.5, 1.5],
                    colors="none", hatches=["///"])


def _flags():
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:20, 0:24]
    ring = (((xx - 11.5) ** 2 + (yy - 9.5) ** 2) > 30).astype(float)          # a hole in the middle
    ring[8:11, 10:13] = 1.0                                                   # with an island in it
    corner = ((xx > 18) & (yy < 4)).astype(float)
    noisy = (rng.random((20, 24)) > 0.6).astype(float)                       # many small regions
    one = np.zeros((20, 24))
    one[5, 7] = 1.0
    return {"ring": ring, "corner": corner, "noisy": noisy, "one": one, "all": np.ones((20, 24))}


@pytest.mark.parametrize("name", ["ring", "corner", "noisy", "one", "all"])
def test_flag_marks_draw_what_the_contour_sets_drew(name):
    flag = _flags()[name]
    xc = np.linspace(-1, 1, 25)[:-1] + 1 / 24
    yc = np.linspace(0, 3, 21)[:-1] + 3 / 40
    old = _pixels(lambda ax: _contour_sets(ax, xc, yc, flag))
    new = _pixels(lambda ax: _flag_marks(ax, xc, yc, flag))
    assert old.shape == new.shape
    assert np.array_equal(old, new), f"{int((old != new).any(2).sum())} pixels differ"
    plain = _pixels(lambda ax: None)
    assert not np.array_equal(plain, new)                                      # the marks drew something

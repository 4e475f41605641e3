"""The live console (rich): link state, rates vs asked, samples learned, confidence, top suggestion."""

from __future__ import annotations

from rich.console import Console, Group
from rich.live import Live
from rich.panel import Panel
from rich.table import Table

__all__ = ["render", "LiveConsole"]


def render(snap: dict):
    """A rich renderable of one session snapshot (:meth:`gcs_sysid.live.session.LiveSession.snapshot`)."""
    head = Table.grid(padding=(0, 2))
    vehicle = snap.get("vehicle")
    head.add_row("link", f"{snap['connection']}  [bold]{snap['link']}[/]",
                 "vehicle", f"sys {vehicle[0]} comp {vehicle[1]}" if vehicle else "-")
    head.add_row("packets", f"{snap['packets']} (raw.tlog {snap['raw_records']})",
                 "corrupt / lost", f"{snap['bad_data']} / {snap['seq_lost']}")
    if "samples_learned" in snap:
        head.add_row("learned", f"{snap['samples_learned']} samples, {snap['steps']} steps",
                     "queue", str(snap["queue"]))
    e = snap.get("edge") or {}
    if "q" in e:
        d = 180 / 3.141592653589793
        head.add_row("live edge", f"p q r {e['p'] * d:.1f} {e['q'] * d:.1f} {e['r'] * d:.1f} deg/s, "
                     f"q_dot {e['q_dot'] * d:.0f} deg/s^2",
                     "air", f"EAS {e.get('eas', float('nan')):.1f} m/s, alpha(AP) "
                     f"{e.get('alpha_ap', float('nan')) * d:.1f} deg")
    rates = Table("message", "Hz", "asked", "request", title="rates", expand=False)
    asked = snap.get("asked", {})
    for name in sorted(set(asked) | set(snap["rates"])):
        got = snap["rates"].get(name, 0.0)
        want = asked.get(name)
        style = "red" if want and got < 0.8 * want else ""
        rates.add_row(name, f"{got:.1f}", f"{want:g}" if want else "", snap["requests"].get(name, ""), style=style)
    conf = Table("coefficient", "confidence", title="confidence", expand=False)
    for name, v in (snap.get("confidence") or {}).items():
        conf.add_row(name, f"{v:.2f}", style="red" if v < snap["params"].get("SID_CONF_MIN", 0.5) else "")
    grid = Table.grid(padding=(0, 4))
    grid.add_row(rates, conf)
    parts = [head, grid]
    if snap.get("top_suggestion"):
        parts.append(Panel(snap["top_suggestion"], title="next maneuver"))
    for line in (snap.get("costs") or []):
        parts.append(f"[red]{line}[/]")
    for line in snap["events"][-5:]:
        parts.append(f"[dim]{line}[/]")
    return Panel(Group(*parts), title="gcs-sysid listen")


class LiveConsole:
    """Context manager showing :func:`render` of the latest snapshot, refreshed by :meth:`update`."""

    def __init__(self, console: Console | None = None):
        self._live = Live(console=console or Console(stderr=True), refresh_per_second=4, transient=False)

    def __enter__(self) -> "LiveConsole":
        self._live.__enter__()
        return self

    def update(self, snap: dict) -> None:
        self._live.update(render(snap))

    def __exit__(self, *exc) -> None:
        self._live.__exit__(*exc)

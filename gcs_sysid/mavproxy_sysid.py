"""MAVProxy module: gcs-sysid inside MAVProxy (thin; the work is in :mod:`gcs_sysid.live.host`).

Load it in MAVProxy (1.8.x loads a module by its dotted import path)::

    module load gcs_sysid.mavproxy_sysid:{"airframe": "plane.toml", "out": "sysid-live"}
    # or: module load gcs_sysid.mavproxy_sysid   then   sysid start plane.toml sysid-live

Commands: ``sysid start AIRFRAME [OUT]``, ``sysid status``, ``sysid suggest``, ``sysid report``,
``sysid save``, ``sysid stop``. ``mavlink_packet`` hands each message to the session and returns;
``idle_task`` runs the schedule. Only this module imports MAVProxy; the package never does.
"""

from __future__ import annotations

from MAVProxy.modules.lib import mp_module

__all__ = ["SysidModule", "init"]


class SysidModule(mp_module.MPModule):
    """The ``sysid`` module (see the module docstring)."""

    def __init__(self, mpstate, airframe: str | None = None, out: str = "sysid-live", learn: bool = True,
                 window: float = 30.0, step: float = 10.0, lag: float = 3.0, min_rows: int = 500,
                 mavsdk: bool = True):
        super().__init__(mpstate, "sysid", "gcs-sysid: live system identification", public=True)
        self.add_command("sysid", self.cmd_sysid, "gcs-sysid live identification",
                         ["start (FILENAME)", "status", "suggest", "report", "save", "stop"])
        self.hosted = None
        self.out = out
        self.learn_kw = dict(window_s=window, step_s=step, lag_s=lag, min_rows=min_rows) if learn else None
        self.mavsdk = mavsdk
        if airframe:
            self.start(airframe, out)

    def start(self, airframe: str, out: str) -> None:
        from gcs_sysid.errors import SysidError
        from gcs_sysid.live.host import HostedSession
        from gcs_sysid.live.learner import LearnOptions

        if self.hosted is not None:
            print("sysid: already running; 'sysid stop' first")
            return
        try:
            learn = LearnOptions(**self.learn_kw) if self.learn_kw is not None else None
            self.hosted = HostedSession(airframe, out, self._write, learn=learn, use_mavsdk=self.mavsdk,
                                        name="mavproxy")
        except SysidError as exc:
            print(f"sysid: error: {exc}")
            return
        self.out = out
        print(f"sysid: listening; raw log {out}/raw.tlog")

    def _write(self, packet: bytes) -> None:
        self.master.write(packet)

    def mavlink_packet(self, m) -> None:
        if self.hosted is not None:
            self.hosted.feed(m)

    def idle_task(self) -> None:
        if self.hosted is not None:
            self.hosted.tick()

    def cmd_sysid(self, args) -> None:
        usage = "usage: sysid <start AIRFRAME [OUT]|status|suggest|report|save|stop>"
        if not args:
            print(usage)
        elif args[0] == "start":
            if len(args) < 2:
                print("usage: sysid start AIRFRAME [OUT]")
            else:
                self.start(args[1], args[2] if len(args) > 2 else self.out)
        elif self.hosted is None:
            print("sysid: not started ('sysid start AIRFRAME [OUT]')")
        elif args[0] == "status":
            print(self.hosted.status())
        elif args[0] == "suggest":
            print(self.hosted.suggest())
        elif args[0] == "report":
            print(f"sysid: report written to {self.hosted.report()}")
        elif args[0] == "save":
            path = self.hosted.save()
            print(f"sysid: model saved to {path}" if path else "sysid: no model yet")
        elif args[0] == "stop":
            self.hosted.close()
            print(f"sysid: stopped; report in {self.out}")
            self.hosted = None
        else:
            print(usage)

    def unload(self) -> None:
        if self.hosted is not None:
            self.hosted.close()
            self.hosted = None


def init(mpstate, **kwargs):
    """MAVProxy's module entry point."""
    return SysidModule(mpstate, **kwargs)

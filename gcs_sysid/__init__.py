"""gcs-sysid: ground-station system identification for fixed-wing UAVs.

Data flow (lower layers never import higher ones)::

    telemetry -> estimation -> aero -> gp -> envelope / maneuvers -> report
                                        sim, diagnose sit beside; cli wires it.
"""

__version__ = "0.1.0"

"""A ground station in its own process: MAVSDK's parameter CLIENT reads and sets gcs-sysid's parameters.

``python mavsdk_param_client.py PORT SYSID COMPID NAME VALUE`` prints one JSON line
``{"before": v0, "after": v1}`` (or ``{"error": ...}``) and exits.
"""

import json
import sys
import time

from mavsdk import ComponentType, Configuration, Mavsdk, log_subscribe
from mavsdk.plugins.param import Param, ParamError, ProtocolVersion


def main() -> int:
    port, sysid, compid = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    name, value = sys.argv[4], float(sys.argv[5])
    log_subscribe(lambda *a: True)
    sdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
    sdk.add_any_connection(f"udpout://127.0.0.1:{port}")
    deadline = time.monotonic() + 10
    system = None
    while system is None and time.monotonic() < deadline:
        system = next((s for s in sdk.get_systems()
                       if s.get_system_id() == sysid and compid in s.component_ids()), None)
        time.sleep(0.1)
    if system is None:
        print(json.dumps({"error": "no system"}))
        return 1
    param = Param(system)
    try:   # mavsdk 4.1's C wrapper reports UNKNOWN here although the component is selected
        param.select_component(compid, ProtocolVersion.V1)
    except ParamError as exc:
        print(f"select_component: {exc}", file=sys.stderr)
    before = param.get_param_float(name)
    param.set_param_float(name, value)
    after = param.get_param_float(name)
    print(json.dumps({"before": before, "after": after}), flush=True)
    sdk.destroy()
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Reading sedbridge's LCM traffic from Python: a recorded log, or live on UDP multicast.

  # after a build (the types are generated into build/lcmtypes/python):
  export PYTHONPATH=build/lcmtypes/python          # installed: PREFIX/share/sedbridge/python
  python3 tools/examples/lcm_python_example.py --log out/replay/bridge.lcmlog
  python3 tools/examples/lcm_python_example.py --live --duration-s 10     # while `run` runs

Live mode subscribes to DISPLAY_COMMAND and FINGERTIP_SED on --url (default: $LCM_DEFAULT_URL,
else LCM's default udpm://239.255.76.67:7667). It uses the real `lcm` module when one is
installed and sedbridge's pure-Python runtime (tools/sedbridge_lcm.py) otherwise.
"""

import argparse
import collections
import sys
import time

try:
    import lcm  # LCM's own binding, where installed (not packaged in Debian 12)
except ImportError:
    import sedbridge_lcm as lcm
import sedbridge_lcm
from sedbridge import lcmt_bridge_status, lcmt_contact_estimate, lcmt_display_command, lcmt_merkel_sed

# lcmt_bridge_status.taxel_health codes (src/lcm/taxel_health_message.h).
TAXEL_HEALTH = {0: "ok", 1: "stuck", 2: "dead", 3: "frozen", 4: "drifting"}


def read_log(path):
    """Prints per-channel counts, the peak display command and Merkel SED of a log, the last
    status's taxel health and the fewest taxels a contact fit used."""
    counts = collections.Counter()
    peak_command, peak_sed, last_status, fewest_used = None, None, None, None
    for event in lcm.EventLog(path, "r"):
        counts[event.channel] += 1
        msg = sedbridge_lcm.decode(event.data)  # any sedbridge type, by fingerprint
        if isinstance(msg, lcmt_display_command):
            if peak_command is None or max(msg.value, default=0) > max(peak_command.value, default=0):
                peak_command = msg
        elif isinstance(msg, lcmt_merkel_sed):
            if peak_sed is None or msg.max_sed_Pa > peak_sed.max_sed_Pa:
                peak_sed = msg
        elif isinstance(msg, lcmt_bridge_status):
            last_status = msg
        elif isinstance(msg, lcmt_contact_estimate) and msg.num_taxels > 0:
            if fewest_used is None or msg.num_taxels_used < fewest_used.num_taxels_used:
                fewest_used = msg
    for channel, n in sorted(counts.items()):
        print("%-18s %6d messages" % (channel, n))
    if peak_sed is not None:
        print("peak Merkel SED: %.1f Pa at utime %d (model %s, %d vertices)"
              % (peak_sed.max_sed_Pa, peak_sed.utime, peak_sed.model_id, peak_sed.num_vertices))
    if peak_command is not None:
        print("peak command: %.2f %s at utime %d (display %s, %d actuators)"
              % (max(peak_command.value), peak_command.unit, peak_command.utime,
                 peak_command.display_id, peak_command.num_actuators))
    if last_status is not None and last_status.num_taxels > 0:
        lying = ["%d %s" % (k, TAXEL_HEALTH.get(code, "?")) for k, code in enumerate(last_status.taxel_health) if code]
        print("taxel health (last status): %s; %d taxel-scans left out" %
              (", ".join(lying) if lying else "all %d ok" % last_status.num_taxels, last_status.taxel_scans_left_out))
    if last_status is not None:
        print("contact scans no model explained within noise: %d" % last_status.model_inadequate_scans)
    if fewest_used is not None:
        left_out = [str(k) for k, used in enumerate(fewest_used.taxel_used) if used in (0, 3)]
        print("contact fit: fewest taxels used %d of %d%s" % (fewest_used.num_taxels_used, fewest_used.num_taxels,
                                                             " (left out: " + " ".join(left_out) + ")" if left_out else ""))
    return 0 if counts else 1


def listen(url, duration_s):
    """Prints one line per DISPLAY_COMMAND and FINGERTIP_SED message for duration_s seconds."""
    lc = lcm.LCM(url) if url else lcm.LCM()

    def on_command(channel, data):
        m = lcmt_display_command.decode(data)
        flags = [n for n in ("clamped", "stale", "fault", "shutdown") if getattr(m, n)]
        print("%s seq %d: max %.2f %s %s" % (channel, m.sequence, max(m.value, default=0), m.unit,
                                           " ".join(flags)))

    def on_sed(channel, data):
        m = lcmt_merkel_sed.decode(data)
        print("%s utime %d: max SED %.1f Pa over %d vertices" % (channel, m.utime, m.max_sed_Pa,
                                                              m.num_vertices))

    lc.subscribe("DISPLAY_COMMAND", on_command)
    lc.subscribe("FINGERTIP_SED", on_sed)
    end = time.monotonic() + duration_s if duration_s > 0 else float("inf")
    try:
        while time.monotonic() < end:
            lc.handle_timeout(100)
    except KeyboardInterrupt:
        pass
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--log", help="an LCM event log, e.g. out/replay/bridge.lcmlog")
    mode.add_argument("--live", action="store_true", help="subscribe on UDP multicast")
    p.add_argument("--url", default="", help="LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)")
    p.add_argument("--duration-s", type=float, default=0, help="live: stop after S seconds (0 = Ctrl-C)")
    a = p.parse_args()
    return read_log(a.log) if a.log else listen(a.url, a.duration_s)


if __name__ == "__main__":
    sys.exit(main())

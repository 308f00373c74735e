#!/usr/bin/env python3
"""Python users of sedbridge's LCM traffic: the generated types and tools/sedbridge_lcm.py.

  test_lcm_python.py --sedbridge build/sedbridge --python-dir build/lcmtypes/python --work DIR

The main check: `sedbridge replay` of the example log, then every event of bridge.lcmlog
decodes with the generated Python types and re-encodes to the same bytes (this failed for
lcmt_tactile_scan while `valid` was a boolean array). The live multicast case skips, saying
why, where multicast does not loop back.
"""

import argparse
import os
import socket
import subprocess
import sys
import unittest

ARGS = None


def setUpModule():
    sys.path.insert(0, ARGS.python_dir)


class ReplayLogRoundTrip(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.out = os.path.join(ARGS.work, "replay")
        subprocess.run([ARGS.sedbridge, "replay", os.path.join(ARGS.root, "config/bridge/example_press.log"),
                        "--out", cls.out, "--no-plots", "--quiet"], check=True, stdout=subprocess.DEVNULL,
                       env=dict(os.environ, LCM_DEFAULT_URL="memq://"))

    def test_every_event_decodes_and_reencodes_to_the_same_bytes(self):
        import sedbridge_lcm
        channels = {}
        for event in sedbridge_lcm.EventLog(os.path.join(self.out, "bridge.lcmlog")):
            msg = sedbridge_lcm.decode(event.data)
            self.assertEqual(msg.encode(), event.data, "%s event %d" % (event.channel, event.eventnum))
            channels.setdefault(event.channel, type(msg).__name__)
        self.assertEqual(channels, {"TACTILE_SCAN": "lcmt_tactile_scan", "FINGERTIP_SED": "lcmt_merkel_sed",
                                    "DISPLAY_COMMAND": "lcmt_display_command",
                                    "BRIDGE_STATUS": "lcmt_bridge_status",
                                    "CONTACT_ESTIMATE": "lcmt_contact_estimate",
                                    "DISPLAY_RENDERING": "lcmt_display_rendering"})

    def test_tactile_scan_valid_flags_are_a_sequence(self):
        import sedbridge_lcm
        from sedbridge import lcmt_tactile_scan
        for event in sedbridge_lcm.EventLog(os.path.join(self.out, "bridge.lcmlog")):
            if event.channel == "TACTILE_SCAN":
                scan = lcmt_tactile_scan.decode(event.data)
                self.assertEqual(len(scan.valid), scan.num_taxels)
                self.assertTrue(all(v in (0, 1) for v in scan.valid))
                scan.valid = list(scan.valid)
                scan.valid[0] = 0
                self.assertEqual(lcmt_tactile_scan.decode(scan.encode()).valid[0], 0)
                return
        self.fail("no TACTILE_SCAN in the log")

    def test_tactile_scan_carries_the_three_axis_sensors_shear(self):
        import sedbridge_lcm
        for event in sedbridge_lcm.EventLog(os.path.join(self.out, "bridge.lcmlog")):
            if event.channel == "TACTILE_SCAN":
                scan = sedbridge_lcm.decode(event.data)
                self.assertEqual(scan.sensor_id, "uskin_4x4")  # three axes: shear per taxel
                self.assertEqual(scan.num_shear, scan.num_taxels)
                self.assertEqual((len(scan.shear_x_kPa), len(scan.shear_y_kPa)), (scan.num_taxels, scan.num_taxels))
                # A scan from before the shear fields (their old fingerprint, no num_shear)
                # still decodes, with num_shear 0.
                old = bytes.fromhex("3afe5a31ff1bfe44") + event.data[8:len(event.data) - 4 - 8 * scan.num_shear]
                earlier = sedbridge_lcm.decode(old)
                self.assertEqual(earlier.num_shear, 0)
                self.assertEqual(list(earlier.pressure_kPa), list(scan.pressure_kPa))
                return
        self.fail("no TACTILE_SCAN in the log")

    def test_example_script_reads_the_log(self):
        r = subprocess.run([sys.executable, os.path.join(ARGS.root, "tools/examples/lcm_python_example.py"),
                            "--log", os.path.join(self.out, "bridge.lcmlog")], capture_output=True, text=True,
                           env=dict(os.environ, PYTHONPATH=ARGS.python_dir))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("DISPLAY_COMMAND", r.stdout)
        self.assertIn("peak Merkel SED", r.stdout)
        self.assertIn("taxel health (last status): all 16 ok", r.stdout)
        self.assertIn("contact fit: fewest taxels used 16 of 16", r.stdout)
        self.assertIn("contact scans no model explained within noise: ", r.stdout)


class EventLogFormat(unittest.TestCase):
    def test_write_then_read(self):
        import sedbridge_lcm
        path = os.path.join(ARGS.work, "written.lcmlog")
        with sedbridge_lcm.EventLog(path, "w") as log:
            log.write_event(5, "A", b"\x01\x02")
            log.write_event(7, "LONG_CHANNEL", b"")
        events = list(sedbridge_lcm.EventLog(path))
        self.assertEqual([(e.eventnum, e.timestamp, e.channel, e.data) for e in events],
                         [(0, 5, "A", b"\x01\x02"), (1, 7, "LONG_CHANNEL", b"")])

    def test_a_non_log_is_an_error(self):
        import sedbridge_lcm
        path = os.path.join(ARGS.work, "not_a_log.lcmlog")
        with open(path, "w") as f:
            f.write("(1700000000.000000) can0 123#00\n" * 3)
        with self.assertRaises(ValueError):
            list(sedbridge_lcm.EventLog(path))


class UdpPackets(unittest.TestCase):
    def test_short_message_round_trip(self):
        import sedbridge_lcm
        lc = sedbridge_lcm.LCM("udpm://239.255.76.67:7667?ttl=0")
        packets = sedbridge_lcm.encode_packets("CH", b"abc", 9)
        self.assertEqual(len(packets), 1)
        self.assertEqual(lc.feed_packet(packets[0]), ("CH", b"abc"))

    def test_fragments_reassemble_in_any_order(self):
        import sedbridge_lcm
        lc = sedbridge_lcm.LCM("udpm://239.255.76.67:7667?ttl=0")
        data = bytes(range(256)) * 40  # 10240 bytes: 8 fragments
        packets = sedbridge_lcm.encode_packets("FINGERTIP_SED", data, 3)
        self.assertGreater(len(packets), 2)
        # Fragments that arrive before fragment 0 cannot be placed and are dropped.
        self.assertEqual([lc.feed_packet(p, "sender") for p in packets[1:]], [None] * (len(packets) - 1))
        # Fragment 0 first, then the rest in reverse order: complete at the last one.
        got = [lc.feed_packet(p, "sender") for p in [packets[0]] + packets[1:][::-1]]
        self.assertEqual(got[:-1], [None] * (len(packets) - 1))
        self.assertEqual(got[-1], ("FINGERTIP_SED", data))

    def test_url_parsing_and_default_from_environment(self):
        import sedbridge_lcm
        self.assertEqual(sedbridge_lcm.parse_udpm_url("udpm://239.1.2.3:1234?ttl=1"), ("239.1.2.3", 1234, 1))
        os.environ["LCM_DEFAULT_URL"] = "udpm://239.9.9.9:4444?ttl=0"
        try:
            self.assertEqual(sedbridge_lcm.parse_udpm_url(""), ("239.9.9.9", 4444, 0))
        finally:
            del os.environ["LCM_DEFAULT_URL"]
        with self.assertRaises(ValueError):
            sedbridge_lcm.parse_udpm_url("tcpq://localhost")


class LiveMulticast(unittest.TestCase):
    def test_publish_and_receive_on_loopback(self):
        import sedbridge_lcm
        url = "udpm://239.255.76.67:%d?ttl=0" % (20000 + (os.getpid() + 11) % 20000)
        try:
            lc = sedbridge_lcm.LCM(url)
            got = []
            lc.subscribe("PY_.*", lambda channel, data: got.append((channel, data)))
        except OSError as e:
            self.skipTest("no multicast here: %s" % e)
        big = os.urandom(5000)
        for _ in range(5):  # a lost datagram on a busy host is retried, not a failure
            try:
                lc.publish("PY_PROBE", b"x")
                lc.publish("PY_BIG", big)
            except OSError as e:
                self.skipTest("multicast send failed: %s (no multicast route?)" % e)
            while lc.handle_timeout(200):
                pass
            if ("PY_BIG", big) in got:
                break
        if not got:
            self.skipTest("multicast on this host does not loop back (%s)" % url)
        self.assertIn(("PY_PROBE", b"x"), got)
        self.assertIn(("PY_BIG", big), got)
        lc.close()


    def test_receives_the_bridge_published_by_lcm_c(self):
        """Interop with LCM's C library: `sedbridge replay --lcm-url` publishes, Python receives.
        FINGERTIP_SED (~7.5 kB) arrives in fragments, so this checks the reassembly too."""
        import sedbridge_lcm
        url = "udpm://239.255.76.67:%d?ttl=0" % (20000 + (os.getpid() + 23) % 20000)
        try:
            lc = sedbridge_lcm.LCM(url)
            got = {}
            lc.subscribe("DISPLAY_COMMAND|FINGERTIP_SED",
                         lambda channel, data: got.setdefault(channel, []).append(data))
            lc.publish("PY_PROBE_SELF", b"x")  # skip where multicast does not loop back
            probe = []
            lc.subscribe("PY_PROBE_SELF", lambda c, d: probe.append(d))
            for _ in range(5):
                if probe:
                    break
                lc.publish("PY_PROBE_SELF", b"x")
                lc.handle_timeout(200)
        except OSError as e:
            self.skipTest("no multicast here: %s" % e)
        if not probe:
            self.skipTest("multicast on this host does not loop back (%s)" % url)
        # Paced at 4x the recorded rate so this reader is not flooded; bounded by the log's length.
        child = subprocess.Popen([ARGS.sedbridge, "replay", os.path.join(ARGS.root, "config/bridge/example_press.log"),
                                  "--out", os.path.join(ARGS.work, "replay_udpm"), "--no-plots", "--quiet",
                                  "--speed", "4", "--lcm-url", url], stdout=subprocess.DEVNULL)
        try:
            while child.poll() is None:
                lc.handle_timeout(100)
            while lc.handle_timeout(300):  # drain what is still queued
                pass
        finally:
            if child.poll() is None:
                child.kill()
            child.wait()
        lc.close()
        self.assertEqual(child.returncode, 0)
        self.assertIn("DISPLAY_COMMAND", got)
        self.assertIn("FINGERTIP_SED", got, "no fragmented message reassembled")
        for channel, messages in got.items():
            for data in messages:
                self.assertEqual(sedbridge_lcm.decode(data).encode(), data, channel)


    def test_lcm_c_receives_what_python_publishes(self):
        """The other way: Python publishes DISPLAY_COMMAND (and a fragmented FINGERTIP_SED),
        `sedbridge display-view --once` (LCM's C library) shows it."""
        import sedbridge_lcm
        from sedbridge import lcmt_display_command, lcmt_merkel_sed
        url = "udpm://239.255.76.67:%d?ttl=0" % (20000 + (os.getpid() + 31) % 20000)
        try:
            lc = sedbridge_lcm.LCM(url)
        except OSError as e:
            self.skipTest("no multicast here: %s" % e)
        cmd = lcmt_display_command()
        cmd.utime, cmd.sequence, cmd.display_id, cmd.unit = 1000000, 7, "suction_4x4", "kPa"
        cmd.num_actuators, cmd.value = 16, [float(i) for i in range(16)]
        sed = lcmt_merkel_sed()
        sed.utime, sed.model_id, sed.num_vertices, sed.num_positions = 1000000, "B", 600, 600
        sed.x_mm = [0.01 * i - 3 for i in range(600)]
        sed.y_mm = [0.0] * 600
        sed.z_mm = [0.0] * 600
        sed.sed_Pa = [float(i) for i in range(600)]
        sed.max_sed_Pa = 599.0
        viewer = subprocess.Popen([ARGS.sedbridge, "display-view", "--lcm-url", url, "--once", "--no-color",
                                   "--duration-s", "20"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            # Publish until the viewer has one command (it exits then), at most 20 s.
            for _ in range(200):
                if viewer.poll() is not None:
                    break
                lc.publish("FINGERTIP_SED", sed.encode())
                lc.publish("DISPLAY_COMMAND", cmd.encode())
                try:
                    viewer.wait(timeout=0.1)
                except subprocess.TimeoutExpired:
                    pass
            out = viewer.communicate(timeout=30)[0]
        finally:
            if viewer.poll() is None:
                viewer.kill()
                viewer.wait()
            lc.close()
        if viewer.returncode == 3 and "0 commands" in out:
            self.skipTest("display-view received nothing: multicast does not loop back here?")
        self.assertEqual(viewer.returncode, 0, out)
        self.assertIn("suction_4x4  seq 7", out)
        self.assertIn("peak 599 Pa", out)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--sedbridge", required=True)
    p.add_argument("--python-dir", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    ARGS, rest = p.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)

#!/usr/bin/env python3
"""`sedbridge view` end to end: the server on a replay's LCM log, the page in headless Chromium.

  test_view_page.py --sedbridge build/sedbridge --python-dir build/lcmtypes/python --work DIR --root SRC

A replay of config/bridge/example_press.log makes the log. The view serves it paused at 1 s;
Chromium (Debian's `chromium`) loads the page, which waits for its first frame and writes what
it shows into #state's data-attributes: the taxel values and the SED range must be the log's
messages at that time (read here with the generated Python types). A screenshot is saved to
DIR/view.png. The server must survive clients that drop mid-stream, malformed requests and 20
streams at once. Without npm's packages the page must still draw its 2-D panels and say what to
run. A replay of the hand example (config/bridge/example_hand.yaml: three fingers, channels
TACTILE_SCAN_THUMB, ...) makes a second log: the page must show one panel per finger, each with
that finger's messages at that time. Exits 77 (skip) without chromium.
"""

import argparse
import glob
import html.parser
import math
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import unittest
import urllib.error
import urllib.request

ARGS = None
START_S = 1.0  # the view starts paused here: the press is under way (force ~0.3 N)


def chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


class StateParser(html.parser.HTMLParser):
    """The data-attributes of <div id="state"> and of each finger panel's .finger-state."""

    def __init__(self):
        super().__init__()
        self.state = None
        self.fingers = []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        data = {k[5:]: v for k, v in attrs.items() if k.startswith("data-")}
        if attrs.get("id") == "state":
            self.state = data
        # The <template>'s own copy has no data-finger.
        if "finger-state" in (attrs.get("class") or "").split() and "finger" in data:
            self.fingers.append(data)


def messages_at(log_path, t_s):
    """The last message of each channel at or before t_s after the log's first event."""
    return messages_at_in_logs([log_path], t_s)


def messages_at_in_logs(log_paths, t_s):
    """messages_at for several logs played as one (their events merged by time)."""
    import sedbridge_lcm
    events = []
    for path in log_paths:
        with sedbridge_lcm.EventLog(path) as log:
            events += list(log)
    events.sort(key=lambda e: e.timestamp)
    last = {}
    for event in events:
        if (event.timestamp - events[0].timestamp) * 1e-6 > t_s + 1e-9:
            break
        last[event.channel] = sedbridge_lcm.decode(event.data)
    return last


def assert_finger_shows(test, shown, scan, sed, command, rendering=None):
    """`shown` (a panel's data-attributes) has these messages' taxels, SED range, command and
    target | delivered SED (rendering: None when the log has none)."""
    test.assertEqual(int(shown["scan-utime"]), scan.utime)
    test.assertEqual(shown["sensor-id"], scan.sensor_id)
    taxels = [float(v) for v in shown["taxels"].split(",")]
    test.assertEqual(len(taxels), scan.num_taxels)
    for k, (a, b) in enumerate(zip(taxels, scan.pressure_kPa)):
        # The frame writes 6 significant digits: within 5e-6 of the value, relative.
        test.assertAlmostEqual(a, b, delta=1e-5 * max(1.0, abs(b)), msg="taxel %d" % k)
    # A three-axis sensor's shear per taxel (the arrows), none for a normal-only one.
    for axis, values in (("shear-x", scan.shear_x_kPa), ("shear-y", scan.shear_y_kPa)):
        test.assertEqual(len(values), scan.num_shear)
        if scan.num_shear == 0:
            test.assertEqual(shown[axis], "")
            continue
        for k, (a, b) in enumerate(zip([float(v) for v in shown[axis].split(",")], values)):
            test.assertAlmostEqual(a, b, delta=1e-5 * max(1.0, abs(b)), msg="%s %d" % (axis, k))
    finite = [v for v in sed.sed_Pa if math.isfinite(v)]
    test.assertEqual(int(shown["sed-utime"]), sed.utime)
    test.assertAlmostEqual(float(shown["sed-min"]), min(finite), delta=1e-6 * max(1.0, min(finite)))
    test.assertAlmostEqual(float(shown["sed-max"]), max(finite), delta=1e-6 * max(finite))
    test.assertEqual(int(shown["sed-matched"]), sed.num_vertices, "SED vertices not on model B's mesh")
    test.assertEqual(int(shown["command-sequence"]), command.sequence)
    test.assertEqual(shown["display-id"], command.display_id)
    if rendering is None:
        test.assertEqual(shown["rendering-sequence"], "")
        return
    test.assertEqual(int(shown["rendering-sequence"]), rendering.command_sequence)
    for key, value in (("target-max", rendering.max_target_sed_Pa), ("delivered-max", rendering.max_delivered_sed_Pa)):
        test.assertAlmostEqual(float(shown[key]), value, delta=1e-5 * max(1.0, abs(value)), msg=key)


def start_view(log, work, name, *extra):
    """Starts `sedbridge view` on `log`, paused at START_S; returns (process, port, log file)."""
    port_file = os.path.join(work, "port_" + name)
    if os.path.exists(port_file):
        os.remove(port_file)
    server_log = open(os.path.join(work, "view_%s.log" % name), "w")
    view = subprocess.Popen([ARGS.sedbridge, "view", "--log", log, "--port", "0", "--port-file", port_file,
                             "--paused", "--start-s", str(START_S), "--duration-s", "240", *extra],
                            stdout=server_log, stderr=subprocess.STDOUT)
    deadline = time.time() + 30
    while not (os.path.exists(port_file) and read_text(port_file).strip()):
        if time.time() > deadline or view.poll() is not None:
            view.kill()
            raise RuntimeError("the view did not start (see %s)" % server_log.name)
        time.sleep(0.1)
    return view, int(read_text(port_file)), server_log


def stop_view(view, server_log):
    view.send_signal(signal.SIGTERM)
    try:
        view.wait(timeout=15)
    except subprocess.TimeoutExpired:
        view.kill()
    server_log.close()


def headless(port, *args):
    return subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--use-gl=swiftshader",
                           "--enable-unsafe-swiftshader", "--virtual-time-budget=8000", "--window-size=1200,1300",
                           *args, "http://127.0.0.1:%d/?close-after=1" % port],
                          capture_output=True, timeout=120)


def read_text(path):
    with open(path) as f:
        return f.read()


def http(port, path, body=None, timeout=10):
    req = urllib.request.Request("http://127.0.0.1:%d%s" % (port, path), data=body,
                                 method="POST" if body is not None else "GET")
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def raw(port, data, read=True, timeout=2):
    """Sends raw bytes; returns what came back (b"" if the server closed)."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(data)
        if not read:
            return b""
        out = b""
        try:
            while len(out) < 65536:
                chunk = s.recv(4096)
                if not chunk:
                    break
                out += chunk
        except socket.timeout:
            pass
        return out


def open_stream(port, timeout=10):
    """Opens /api/events and returns (socket, first bytes up to the first frame)."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    s.sendall(b"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept: text/event-stream\r\n\r\n")
    got = b""
    while b"event: frame" not in got and len(got) < 1 << 20:
        chunk = s.recv(65536)
        if not chunk:
            break
        got += chunk
    return s, got


class ViewPage(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.log = os.path.join(ARGS.work, "replay", "bridge.lcmlog")
        subprocess.run([ARGS.sedbridge, "replay", os.path.join(ARGS.root, "config/bridge/example_press.log"),
                        "--out", os.path.join(ARGS.work, "replay"), "--no-plots", "--quiet"], check=True,
                       stdout=subprocess.DEVNULL, env=dict(os.environ, LCM_DEFAULT_URL="memq://"))
        cls.view, cls.port, cls.server_log = start_view(cls.log, ARGS.work, "finger")
        cls.expected = messages_at(cls.log, START_S)

    @classmethod
    def tearDownClass(cls):
        stop_view(cls.view, cls.server_log)

    def chromium(self, *args):
        return headless(self.port, *args)

    def assertAlive(self):
        self.assertIsNone(self.view.poll(), "the view exited")
        status, body = http(self.port, "/api/frame")
        self.assertEqual(status, 200)

    def test_1_page_shows_the_log_at_that_time(self):
        run = self.chromium("--dump-dom")
        self.assertEqual(run.returncode, 0, run.stderr[-2000:])
        parser = StateParser()
        parser.feed(run.stdout.decode("utf-8", "replace"))
        state = parser.state
        self.assertIsNotNone(state, "no #state in the DOM")
        self.assertGreaterEqual(int(state["frames"]), 1, "the page drew no frame")
        # Without npm's packages the build still works and the page says so (test_7).
        vendored = os.path.exists(os.path.join(ARGS.web_dir, "vendor", "three.module.min.js"))
        self.assertEqual(state.get("libs"), "ok" if vendored else "missing")
        # One finger (the plain channel names): one panel, named "".
        self.assertEqual(state["fingers"], "")
        self.assertEqual(state["panels"], "1")
        self.assertEqual(len(parser.fingers), 1)
        # The example's suction display is rendered by inverse FE: DISPLAY_RENDERING is on the
        # bus, its delivered SED shown beside the target.
        rendering = self.expected["DISPLAY_RENDERING"]
        self.assertGreater(rendering.max_target_sed_Pa, 0)
        self.assertGreater(rendering.max_delivered_sed_Pa, 0)
        for shown in (state, parser.fingers[0]):
            assert_finger_shows(self, shown, self.expected["TACTILE_SCAN"], self.expected["FINGERTIP_SED"],
                                self.expected["DISPLAY_COMMAND"], rendering)
        self.assertGreater(max(float(v) for v in state["taxels"].split(",")), 1.0, "the scan at 1 s should press (kPa)")
        self.assertEqual(self.expected["TACTILE_SCAN"].num_shear, 16, "uskin_4x4: shear per taxel")
        self.assertAlmostEqual(float(state["position-s"]), START_S)
        # The 3-D panel: model B's skin, each vertex over the Merkel layer coloured by the
        # SED of the Merkel vertex beneath it (the field covers the whole layer here).
        if state.get("webgl") == "yes":
            import json
            mesh = json.loads(http(self.port, "/api/mesh")[1])["meshes"][0]
            self.assertEqual(len(mesh["skin_merkel"]), len(mesh["skin"]["xyz_mm"]) // 3)
            self.assertEqual(state["tip-surface"], "skin")
            self.assertEqual(int(state["skin-coloured"]), sum(1 for k in mesh["skin_merkel"] if k >= 0))
            self.assertGreater(int(state["skin-coloured"]), 0)

    def test_2_screenshot(self):
        shot = os.path.join(ARGS.work, "view.png")
        if os.path.exists(shot):
            os.remove(shot)
        run = self.chromium("--screenshot=" + shot)
        self.assertEqual(run.returncode, 0, run.stderr[-2000:])
        with open(shot, "rb") as f:
            head = f.read(24)
        self.assertEqual(head[:8], b"\x89PNG\r\n\x1a\n")
        self.assertEqual(struct.unpack(">II", head[16:24]), (1200, 1300))
        self.assertGreater(os.path.getsize(shot), 20000, "a blank page?")

    def test_3_client_dropping_mid_stream(self):
        for _ in range(5):
            s, got = open_stream(self.port)
            self.assertIn(b"event: frame", got)
            # Close with a reset (SO_LINGER 0), not a polite FIN.
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            s.close()
        # Drop one while frames flow: play, read a little, drop.
        self.assertEqual(http(self.port, "/api/control", b"play")[0], 200)
        s, got = open_stream(self.port)
        s.recv(4096)
        s.close()
        self.assertEqual(http(self.port, "/api/control", b"pause")[0], 200)
        self.assertAlive()

    def test_4_malformed_requests(self):
        replies = [
            raw(self.port, b"\x00\x01\x02 not http at all\r\n\r\n"),
            raw(self.port, b"GET /" + b"a" * 20000 + b" HTTP/1.1\r\nHost: x\r\n\r\n"),
            raw(self.port, b"GET / HTTP/1.1\r\n" + b"X-Junk: " + b"b" * 100000 + b"\r\n\r\n"),
            raw(self.port, b"POST /api/control HTTP/1.1\r\nHost: x\r\nContent-Length: 99999999\r\n\r\nplay"),
            raw(self.port, b"GET /api/frame HTTP/1.1\r\nHost: x\r\n", read=False),  # never finished
            raw(self.port, b"GET /../../../../etc/passwd HTTP/1.1\r\nHost: x\r\n\r\n"),
        ]
        self.assertNotIn(b"root:", replies[-1], "the mount point served a file outside the page")
        self.assertEqual(http(self.port, "/api/control", b"rm -rf /")[0], 400)
        self.assertEqual(http(self.port, "/api/control", b"seek nan")[0], 400)
        self.assertEqual(http(self.port, "/no/such/page")[0], 404)
        self.assertAlive()

    def test_5_twenty_streams_at_once(self):
        results = []

        def client():
            try:
                s, got = open_stream(self.port, timeout=20)
                results.append(b"event: frame" in got)
                time.sleep(0.5)
                s.close()
            except OSError as e:
                results.append(e)

        threads = [threading.Thread(target=client) for _ in range(20)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
        self.assertEqual(results, [True] * 20)
        self.assertAlive()

    def test_6_playback_controls(self):
        self.assertEqual(http(self.port, "/api/control", b"seek 2.5")[0], 200)
        time.sleep(0.3)
        import json
        frame = json.loads(http(self.port, "/api/frame")[1])
        self.assertAlmostEqual(frame["playback"]["position_s"], 2.5)
        self.assertFalse(frame["playback"]["playing"])
        self.assertEqual(http(self.port, "/api/control", b"seek %g" % START_S)[0], 200)


class ViewPageOfAHand(unittest.TestCase):
    """The hand example: three fingers, a panel each, each with its own channels' messages."""

    @classmethod
    def setUpClass(cls):
        # The replay writes one log a finger (hand/<finger>/bridge.lcmlog); the view plays the
        # folder's logs as one.
        out = os.path.join(ARGS.work, "hand")
        shutil.rmtree(out, ignore_errors=True)
        subprocess.run([ARGS.sedbridge, "replay", os.path.join(ARGS.root, "config/bridge/example_hand.log"),
                        "--config", os.path.join(ARGS.root, "config/bridge/example_hand.yaml"),
                        "--out", out, "--no-plots", "--quiet"], check=True, cwd=ARGS.work,
                       stdout=subprocess.DEVNULL, env=dict(os.environ, LCM_DEFAULT_URL="memq://"))
        cls.view, cls.port, cls.server_log = start_view(out, ARGS.work, "hand")
        cls.expected = messages_at_in_logs(sorted(glob.glob(os.path.join(out, "*", "bridge.lcmlog"))), START_S)

    @classmethod
    def tearDownClass(cls):
        stop_view(cls.view, cls.server_log)

    def test_8_one_panel_per_finger_with_its_messages(self):
        fingers = [c[len("TACTILE_SCAN_"):] for c in self.expected if c.startswith("TACTILE_SCAN_")]
        self.assertEqual(sorted(fingers), ["INDEX", "MIDDLE", "THUMB"])
        run = headless(self.port, "--dump-dom")
        self.assertEqual(run.returncode, 0, run.stderr[-2000:])
        parser = StateParser()
        parser.feed(run.stdout.decode("utf-8", "replace"))
        self.assertEqual(sorted(parser.state["fingers"].split(",")), sorted(fingers))
        self.assertEqual(int(parser.state["panels"]), 3)
        shown = {f["finger"]: f for f in parser.fingers}
        self.assertEqual(sorted(shown), sorted(fingers))
        for name in fingers:
            with self.subTest(finger=name):
                assert_finger_shows(self, shown[name], self.expected["TACTILE_SCAN_" + name],
                                    self.expected["FINGERTIP_SED_" + name], self.expected["DISPLAY_COMMAND_" + name],
                                    self.expected.get("DISPLAY_RENDERING_" + name))
        # The fingers differ (not one finger's messages shown thrice): the index has its own
        # sensor (cyskin_16) and display (pin_6x4).
        self.assertEqual(shown["INDEX"]["sensor-id"], "cyskin_16")
        self.assertEqual(shown["INDEX"]["display-id"], "pin_6x4")
        self.assertEqual(shown["THUMB"]["sensor-id"], "uskin_4x4")
        # uskin_4x4 has three axes (shear arrows), cyskin_16 one.
        self.assertEqual(self.expected["TACTILE_SCAN_THUMB"].num_shear, 16)
        self.assertEqual(self.expected["TACTILE_SCAN_INDEX"].num_shear, 0)

    def test_9_screenshot_of_the_hand(self):
        shot = os.path.join(ARGS.work, "view_hand.png")
        if os.path.exists(shot):
            os.remove(shot)
        run = headless(self.port, "--screenshot=" + shot)
        self.assertEqual(run.returncode, 0, run.stderr[-2000:])
        self.assertGreater(os.path.getsize(shot), 20000, "a blank page?")


class ViewPageWithoutLibraries(unittest.TestCase):
    def test_7_page_says_what_to_run(self):
        web = os.path.join(ARGS.work, "web_without_npm")
        shutil.rmtree(web, ignore_errors=True)
        subprocess.run([ARGS.cmake, "-DSRC=" + os.path.join(ARGS.root, "src/view/web"), "-DNODE_MODULES=" + web + "/none",
                        "-DDEST=" + web, "-P", os.path.join(ARGS.root, "tools/cmake/CopyViewWeb.cmake")],
                       check=True, stdout=subprocess.DEVNULL)
        port_file = os.path.join(ARGS.work, "port_without_npm")
        if os.path.exists(port_file):
            os.remove(port_file)
        view = subprocess.Popen([ARGS.sedbridge, "view", "--log", os.path.join(ARGS.work, "replay", "bridge.lcmlog"),
                                 "--web-dir", web, "--port", "0", "--port-file", port_file, "--paused",
                                 "--duration-s", "120"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            deadline = time.time() + 30
            while not (os.path.exists(port_file) and read_text(port_file).strip()):
                self.assertLess(time.time(), deadline, "the view did not start")
                time.sleep(0.1)
            port = int(read_text(port_file))
            run = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=5000",
                                  "--dump-dom", "http://127.0.0.1:%d/?close-after=1" % port],
                                 capture_output=True, timeout=120)
            dom = run.stdout.decode("utf-8", "replace")
            parser = StateParser()
            parser.feed(dom)
            self.assertEqual(parser.state.get("libs"), "missing")
            self.assertGreaterEqual(int(parser.state["frames"]), 1, "the 2-D panels still draw")
            self.assertIn("run tools/setup.sh (npm ci in tools/view-web)", dom)
        finally:
            view.terminate()
            view.wait(15)


def main():
    global ARGS
    p = argparse.ArgumentParser()
    p.add_argument("--sedbridge", required=True)
    p.add_argument("--python-dir", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--root", required=True)
    p.add_argument("--web-dir", required=True, help="the build's view_web")
    p.add_argument("--cmake", default="cmake")
    ARGS, rest = p.parse_known_args()
    if chromium() is None:
        print("SKIP: no chromium (Debian: apt-get install chromium; tools/setup.sh installs it)")
        return 77
    sys.path.insert(0, ARGS.python_dir)
    result = unittest.main(argv=[sys.argv[0]] + rest, exit=False, verbosity=2).result
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Measures `sedbridge view`: the view's CPU at 30 Hz (no page, one page in
headless Chromium, 20 event streams), the page's frame and draw rates, and the bridge's
per-scan latency with and without a view and a page on the bus.

  tools/measure_view.py --sedbridge build/sedbridge [--work /tmp/measure_view] [--bridge-cpu 0] [--rounds 2]

--bridge-cpu N runs the bridge on CPU N and the view and the browser on the others (as a lab
would run a bridge beside a viewer): on a machine of few cores the headless browser's software
WebGL otherwise takes the bridge's core, and the latency measured is that contention's, not
the view's.

The page's rates are read from its #state data-attributes through Chromium's DevTools
protocol (a minimal WebSocket client below: the standard library has none). Everything runs
on 127.0.0.1 and ends by itself. Numbers on a shared 2-core machine are noisy: repeat.
"""

import argparse
import base64
import json
import os
import re
import shutil
import socket
import struct
import subprocess
import tempfile
import threading
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cpu_s(pid):
    fields = open("/proc/%d/stat" % pid).read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def cpu_percent(pid, seconds):
    c0, t0 = cpu_s(pid), time.time()
    time.sleep(seconds)
    return 100 * (cpu_s(pid) - c0) / (time.time() - t0)


def pinned(cpus):
    """preexec_fn that keeps a child (and what it starts) on `cpus` (None: anywhere)."""
    return (lambda: os.sched_setaffinity(0, cpus)) if cpus else None


def start_view(args, extra):
    port_file = os.path.join(args.work, "port")
    if os.path.exists(port_file):
        os.remove(port_file)
    view = subprocess.Popen([args.sedbridge, "view", "--port", "0", "--port-file", port_file, "--duration-s", "300"] + extra,
                            stderr=open(os.path.join(args.work, "view.log"), "a"), preexec_fn=pinned(args.view_cpus))
    deadline = time.time() + 30
    while not (os.path.exists(port_file) and open(port_file).read().strip()):
        if time.time() > deadline or view.poll() is not None:
            raise RuntimeError("the view did not start")
        time.sleep(0.1)
    return view, int(open(port_file).read())


class DevTools:
    """Just enough of the DevTools protocol over a WebSocket to evaluate an expression."""

    def __init__(self, ws_url):
        m = re.match(r"ws://([^:/]+):(\d+)(/.*)", ws_url)
        self.sock = socket.create_connection((m.group(1), int(m.group(2))), timeout=10)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall(("GET %s HTTP/1.1\r\nHost: %s:%s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                           "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n\r\n"
                           % (m.group(3), m.group(1), m.group(2), key)).encode())
        reply = b""
        while b"\r\n\r\n" not in reply:
            reply += self.sock.recv(4096)
        self.buf = reply.split(b"\r\n\r\n", 1)[1]
        self.next_id = 1

    def _recv(self, n):
        while len(self.buf) < n:
            self.buf += self.sock.recv(65536)
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def _frame(self):
        b0, b1 = self._recv(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack(">H", self._recv(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", self._recv(8))[0]
        return b0 & 0x0F, self._recv(n)

    def evaluate(self, expression):
        msg_id = self.next_id
        self.next_id += 1
        payload = json.dumps({"id": msg_id, "method": "Runtime.evaluate",
                              "params": {"expression": expression, "returnByValue": True}}).encode()
        mask = os.urandom(4)
        header = bytes([0x81]) + (bytes([0x80 | len(payload)]) if len(payload) < 126
                                  else bytes([0x80 | 126]) + struct.pack(">H", len(payload)))
        self.sock.sendall(header + mask + bytes(c ^ mask[i % 4] for i, c in enumerate(payload)))
        while True:
            opcode, data = self._frame()
            if opcode == 1:
                reply = json.loads(data)
                if reply.get("id") == msg_id:
                    return reply["result"]["result"].get("value")


def open_page(port, work, cpus=None):
    profile = tempfile.mkdtemp(dir=work)
    chrome = subprocess.Popen([shutil.which("chromium"), "--headless", "--no-sandbox", "--use-gl=swiftshader",
                               "--enable-unsafe-swiftshader", "--window-size=1200,1300", "--user-data-dir=" + profile,
                               "--remote-debugging-port=0", "http://127.0.0.1:%d/" % port],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, preexec_fn=pinned(cpus))
    active = os.path.join(profile, "DevToolsActivePort")
    deadline = time.time() + 30
    while not (os.path.exists(active) and len(open(active).read().split()) >= 1):
        if time.time() > deadline:
            raise RuntimeError("chromium did not open its DevTools port")
        time.sleep(0.2)
    debug_port = int(open(active).read().split()[0])
    for _ in range(50):
        targets = json.load(urllib.request.urlopen("http://127.0.0.1:%d/json" % debug_port))
        pages = [t for t in targets if t.get("type") == "page"]
        if pages:
            return chrome, DevTools(pages[0]["webSocketDebuggerUrl"])
        time.sleep(0.2)
    raise RuntimeError("no page target")


def replay_latency(args, url):
    out = subprocess.run([args.sedbridge, "replay", os.path.join(ROOT, "config/bridge/example_press.log"), "--no-plots",
                          "--quiet", "--lcm-url", url], capture_output=True, text=True, check=True,
                         preexec_fn=pinned(args.bridge_cpus)).stdout
    m = re.search(r"latency median ([\d.]+) ms, p99 ([\d.]+) ms", out)
    return float(m.group(1)), float(m.group(2))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sedbridge", default=os.path.join(ROOT, "build", "sedbridge"))
    p.add_argument("--work", default=os.path.join(tempfile.gettempdir(), "measure_view"))
    p.add_argument("--seconds", type=float, default=8)
    p.add_argument("--bridge-cpu", type=int, help="run the bridge on this CPU, the view and the browser on the others")
    p.add_argument("--rounds", type=int, default=2, help="latency rounds, each without and with a view (alternating)")
    args = p.parse_args()
    args.bridge_cpus = args.view_cpus = None
    if args.bridge_cpu is not None:
        everything = os.sched_getaffinity(0)
        if args.bridge_cpu not in everything or len(everything) < 2:
            p.error("--bridge-cpu needs a CPU of this process's %s and at least one other" % sorted(everything))
        args.bridge_cpus, args.view_cpus = {args.bridge_cpu}, everything - {args.bridge_cpu}
    os.makedirs(args.work, exist_ok=True)
    subprocess.run([args.sedbridge, "replay", os.path.join(ROOT, "config/bridge/example_press.log"), "--out",
                    os.path.join(args.work, "replay"), "--no-plots", "--quiet"], check=True, stdout=subprocess.DEVNULL,
                   env=dict(os.environ, LCM_DEFAULT_URL="memq://"))
    log = os.path.join(args.work, "replay", "bridge.lcmlog")

    # 1. CPU at 30 Hz: the 3 s log at 0.05x plays for 60 s, a new frame every tick.
    view, port = start_view(args, ["--log", log, "--speed", "0.05"])
    print("view, log playing (a frame every 1/30 s):")
    print("  no page:            CPU %.1f %% of one core" % cpu_percent(view.pid, args.seconds))
    if shutil.which("chromium"):
        chrome, tools = open_page(port, args.work, args.view_cpus)
        time.sleep(3)
        cpu = cpu_percent(view.pid, args.seconds)
        state = json.loads(tools.evaluate("JSON.stringify(document.getElementById('state').dataset)"))
        print("  one page open:      CPU %.1f %% of one core; the page: %s frames/s received, %s draws/s"
              % (cpu, state.get("frameHz"), state.get("drawHz")))
        chrome.terminate()
        chrome.wait()
    stop = threading.Event()
    counts = []

    def stream():
        s = socket.create_connection(("127.0.0.1", port), timeout=10)
        s.sendall(b"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        n, t0 = 0, time.time()
        while not stop.is_set():
            data = s.recv(1 << 20)
            if not data:
                break
            n += data.count(b"event: frame")
        counts.append(n / (time.time() - t0))
        s.close()

    threads = [threading.Thread(target=stream) for _ in range(20)]
    for t in threads:
        t.start()
    time.sleep(1)
    cpu = cpu_percent(view.pid, args.seconds)
    stop.set()
    for t in threads:
        t.join(20)
    print("  20 event streams:   CPU %.1f %% of one core; %.1f frames/s per stream" % (cpu, sum(counts) / len(counts)))
    view.terminate()
    view.wait()

    # 2. The bridge's per-scan latency (replay: as fast as it can, publishing on UDP multicast)
    # without and with a live view + page on the same bus, alternating.
    url = "udpm://239.255.76.67:7653?ttl=0"
    rows = []
    for with_view in (False, True) * args.rounds:
        chrome = view = None
        if with_view:
            view, port = start_view(args, ["--lcm-url", url])
            if shutil.which("chromium"):
                chrome, _ = open_page(port, args.work, args.view_cpus)
                time.sleep(2)
        rows.append((with_view, replay_latency(args, url)))
        for proc in (chrome, view):
            if proc:
                proc.terminate()
                proc.wait()
    where = (" the bridge on CPU %d, the view and the browser on %s" % (args.bridge_cpu, sorted(args.view_cpus))
             if args.bridge_cpu is not None else "")
    print("bridge per-scan latency (replay of the example, median / p99 ms)%s:" % (";" + where if where else ""))
    for with_view, (p50, p99) in rows:
        print("  %-22s %.3f / %.3f" % ("view + page open:" if with_view else "no view:", p50, p99))


if __name__ == "__main__":
    main()

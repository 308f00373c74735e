#!/usr/bin/python3
"""Render display frames (written by `sedbridge display-view --log ... --png-dir/--animation`)
as PNG images and/or an animated GIF.

Input: frames.jsonl — a header line {display_id, unit, max, x_mm, y_mm} and one line per
frame {utime, sequence, value, clamped, stale, fault, shutdown, sed: {x_mm, y_mm, z_mm, sed_Pa}
or null}. Each image shows the Merkel-layer SED under the pad (left) and the actuator
array of the haptic display (right), both in the pad frame (x lateral, y toward the tip).

Run with /usr/bin/python3 (needs matplotlib; Debian: python3-matplotlib).
"""
import argparse
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import animation  # noqa: E402


def load(path):
    with open(path) as f:
        header = json.loads(f.readline())
        frames = [json.loads(line) for line in f if line.strip()]
    return header, frames


def finite(v):
    return v is not None and math.isfinite(v)


def pitch(xs):
    s = sorted(set(round(x, 3) for x in xs))
    d = [b - a for a, b in zip(s, s[1:]) if b - a > 1e-6]
    return min(d) if d else 2.0


class Figure:
    def __init__(self, header, frames):
        self.h = header
        self.frames = frames
        xs, ys = header["x_mm"], header["y_mm"]
        p = min(pitch(xs), pitch(ys))
        self.marker_area = (p * 0.8 * 72 / 25.4 * 4) ** 2  # points^2, roughly a pitch wide
        self.xlim = (min(xs) - 2 * p, max(xs) + 2 * p)
        self.ylim = (min(ys) - 2 * p, max(ys) + 2 * p)
        peaks = [max([s for s in (f["sed"] or {}).get("sed_Pa", []) if finite(s)] or [0])
                 for f in frames]
        self.sed_max = max(peaks + [1e-9])
        self.fig, (self.ax_sed, self.ax_cmd) = plt.subplots(1, 2, figsize=(10, 4.8))
        self.cbar_done = False

    def draw(self, i):
        f = self.frames[i]
        h = self.h
        for ax in (self.ax_sed, self.ax_cmd):
            ax.clear()
            ax.set_aspect("equal")
            ax.set_xlim(*self.xlim)
            ax.set_ylim(*self.ylim)
            ax.set_xlabel("x [mm] (lateral)")
        self.ax_sed.set_ylabel("y [mm] (toward the tip)")
        sed = f.get("sed")
        if sed:
            pts = [(x, y, s) for x, y, z, s in zip(sed["x_mm"], sed["y_mm"],
                                                   sed["z_mm"] or [0] * len(sed["x_mm"]),
                                                   sed["sed_Pa"])
                   if finite(x) and finite(y) and finite(s) and (not finite(z) or z > -6)]
            if pts:
                sc = self.ax_sed.scatter([p[0] for p in pts], [p[1] for p in pts],
                                         c=[p[2] for p in pts], cmap="inferno", s=18,
                                         vmin=0, vmax=self.sed_max)
                if not self.cbar_done:
                    self.fig.colorbar(sc, ax=self.ax_sed, label="SED [Pa]")
        # actuator sites over the field, to see which SED each one samples
        self.ax_sed.scatter(h["x_mm"], h["y_mm"], marker="+", c="c", s=30, linewidths=0.8)
        self.ax_sed.set_title("Merkel-layer SED (+ = actuator sites)")
        vmax = h["max"] if finite(h["max"]) and h["max"] > 0 else 1.0
        vals = [v if finite(v) else float("nan") for v in f["value"]]
        n = min(len(vals), len(h["x_mm"]))
        cs = self.ax_cmd.scatter(h["x_mm"][:n], h["y_mm"][:n], c=vals[:n], cmap="viridis",
                                 vmin=0, vmax=vmax, s=self.marker_area, marker="s",
                                 edgecolors="k")
        for x, y, v in zip(h["x_mm"][:n], h["y_mm"][:n], vals[:n]):
            self.ax_cmd.text(x, y, "nan" if math.isnan(v) else f"{v:.2g}", ha="center",
                             va="center", fontsize=7,
                             color="k" if (not math.isnan(v) and v > 0.6 * vmax) else "w")
        if not self.cbar_done:
            self.fig.colorbar(cs, ax=self.ax_cmd, label=f"command [{h['unit']}]")
            self.cbar_done = True
        flags = [k.upper() for k in ("clamped", "stale", "fault", "shutdown") if f.get(k)]
        self.ax_cmd.set_title(f"{h['display_id']} command" + (" [" + ", ".join(flags) + "]"
                                                              if flags else ""))
        t0 = self.frames[0]["utime"]
        self.fig.suptitle(f"t = {(f['utime'] - t0) * 1e-6:.3f} s   seq {f['sequence']}")
        return []


def progress(what, done, total):
    """One line on stderr every 10 % (and at the end), so a long render shows it is alive."""
    step = max(1, total // 10)
    if done == total or done % step == 0:
        print(f"  {what}: {done}/{total} frames", file=sys.stderr, flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("frames", help="frames.jsonl from sedbridge display-view")
    ap.add_argument("--png-dir", help="write frame_00000.png ... here")
    ap.add_argument("--animation", help="write an animated GIF here")
    ap.add_argument("--fps", type=float, default=10.0, help="GIF frame rate")
    a = ap.parse_args()
    if not a.png_dir and not a.animation:
        ap.error("nothing to do: give --png-dir and/or --animation")
    header, frames = load(a.frames)
    if not frames:
        sys.exit("no frames in " + a.frames)
    fig = Figure(header, frames)
    if a.png_dir:
        os.makedirs(a.png_dir, exist_ok=True)
        for i in range(len(frames)):
            fig.draw(i)
            fig.fig.savefig(os.path.join(a.png_dir, f"frame_{i:05d}.png"), dpi=80)
            progress("PNG", i + 1, len(frames))
        print(f"wrote {len(frames)} PNG frames to {a.png_dir}")
    if a.animation:
        anim = animation.FuncAnimation(fig.fig, fig.draw, frames=len(frames), blit=False)
        anim.save(a.animation, writer=animation.PillowWriter(fps=max(1.0, a.fps)), dpi=70,
                  progress_callback=lambda i, n: progress("GIF", i + 1, n))
        print(f"wrote {a.animation} ({len(frames)} frames)")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The command line as a lab uses it: LCM URL precedence, honest exits on wrong input.

  test_lab_cli.py --sedbridge build/sedbridge --work DIR [--root SRC]
"""

import argparse
import os
import subprocess
import sys
import unittest

ARGS = None


def sedbridge(*args, env=None):
    """(exit status, stdout + stderr) of the built program."""
    full_env = dict(os.environ)
    full_env.pop("LCM_DEFAULT_URL", None)
    full_env.update(env or {})
    r = subprocess.run([ARGS.sedbridge] + list(args), capture_output=True, text=True, env=full_env, timeout=300)
    return r.returncode, r.stdout + r.stderr


def src(path):
    return os.path.join(ARGS.root, path)


def memq_config():
    """B_coarse with lcm.url memq:// (nothing leaves the process)."""
    path = os.path.join(ARGS.work, "memq_bridge.yaml")
    with open(path, "w") as f:
        f.write('fe: {model: B_coarse, preset: fast}\nlcm: {url: "memq://"}\n')
    return path


class LcmUrlPrecedence(unittest.TestCase):
    """--lcm-url > $LCM_DEFAULT_URL > the command's fallback (src/app/lcm_url.h)."""

    def run_live(self, *extra, env=None):
        return sedbridge("run", "--config", memq_config(), "--log-input", src("config/bridge/example_press.log"),
                         "--duration-s", "0.1", *extra, env=env)

    def test_run_uses_the_config_url_without_flag_or_environment(self):
        status, out = self.run_live()
        self.assertEqual(status, 0, out)
        self.assertIn("LCM memq:// (from config lcm.url)", out)

    def test_run_honours_lcm_default_url(self):
        status, out = self.run_live(env={"LCM_DEFAULT_URL": "memq://?env=1"})
        self.assertEqual(status, 0, out)
        self.assertIn("LCM memq://?env=1 (from LCM_DEFAULT_URL)", out)

    def test_the_flag_beats_the_environment(self):
        status, out = self.run_live("--lcm-url", "memq://?flag=1", env={"LCM_DEFAULT_URL": "memq://?env=1"})
        self.assertEqual(status, 0, out)
        self.assertIn("LCM memq://?flag=1 (from --lcm-url)", out)

    def test_replay_honours_lcm_default_url(self):
        status, out = sedbridge("replay", src("config/bridge/example_press.log"), "--config", memq_config(),
                                "--out", os.path.join(ARGS.work, "replay_env"), "--no-plots", "--quiet",
                                env={"LCM_DEFAULT_URL": "memq://?env=1"})
        self.assertEqual(status, 0, out)
        self.assertIn("also publishing on memq://?env=1 (from LCM_DEFAULT_URL)", out)

    def test_display_view_honours_lcm_default_url_and_its_flag(self):
        status, out = sedbridge("display-view", "--duration-s", "0.1", env={"LCM_DEFAULT_URL": "memq://?env=1"})
        self.assertEqual(status, 3, out)  # 3: nothing received (memq has no other publisher)
        self.assertIn("listening on memq://?env=1", out)
        status, out = sedbridge("display-view", "--duration-s", "0.1", "--lcm-url", "memq://?flag=1",
                                env={"LCM_DEFAULT_URL": "memq://?env=1"})
        self.assertIn("listening on memq://?flag=1", out)

    def test_an_empty_flag_is_a_usage_error(self):
        status, out = self.run_live("--lcm-url=")
        self.assertEqual(status, 2, out)


class HonestExits(unittest.TestCase):
    """replay exits non-zero, saying why, when nothing in the log is usable."""

    def replay(self, log, *extra):
        return sedbridge("replay", log, "--out", os.path.join(ARGS.work, "replay_exit"), "--no-plots", "--quiet",
                         *extra)

    def test_a_file_that_is_not_a_candump_log(self):
        status, out = self.replay(src("README.md"))
        self.assertEqual(status, 1, out)
        self.assertIn("is not a candump -l log", out)

    def test_a_log_that_matches_nothing_in_the_profile(self):
        status, out = self.replay(src("config/bridge/example_press.log"), "--profile", "cyskin_16")
        self.assertEqual(status, 1, out)
        self.assertIn("none of them made a scan of sensor profile 'cyskin_16'", out)

    def test_profile_selects_the_sensor(self):
        status, out = self.replay(src("config/bridge/example_press.log"), "--profile", "uskin_4x4")
        self.assertEqual(status, 0, out)
        self.assertIn("(sensor uskin_4x4,", out)

    def mixed_log(self):
        """The example log with every frame repeated on can1: what `candump -l any` gives."""
        path = os.path.join(ARGS.work, "mixed.log")
        with open(src("config/bridge/example_press.log")) as f, open(path, "w") as out:
            for line in f:
                out.write(line)
                out.write(line.replace(" can0 ", " can1 "))
        return path

    def test_interface_keeps_one_bus_of_a_mixed_log(self):
        status, out = self.replay(self.mixed_log(), "--interface", "can1")
        self.assertEqual(status, 0, out)
        self.assertIn("scans: 300 (stepped 300, rejected 0", out)
        self.assertIn("frames: 4800 (rejected 0,", out)
        self.assertNotIn("mixes interfaces", out)

    def test_a_mixed_log_without_interface_warns(self):
        status, out = self.replay(self.mixed_log())
        self.assertEqual(status, 0, out)
        self.assertIn("the log mixes interfaces (can0, can1)", out)

    def test_an_interface_the_log_does_not_have(self):
        status, out = self.replay(self.mixed_log(), "--interface", "can7")
        self.assertEqual(status, 1, out)
        self.assertIn("none of the 9600 frames is on the chosen interface (the log has: can0, can1)", out)

    def test_simulate_takes_profile(self):
        status, out = sedbridge("simulate", src("config/scenes/sensor_sphere_press.yaml"), "--profile", "cyskin_16",
                                "--duration-s", "0.1", "--out", os.path.join(ARGS.work, "simulate_profile"),
                                "--no-plots", "--quiet")
        self.assertEqual(status, 0, out)
        self.assertIn("sensor cyskin_16", out)


def data_array(xml_text, name):
    """Numbers of the <DataArray Name="name"> (or of <Points> for name=None) in a .vtu."""
    import xml.etree.ElementTree as ET
    root = ET.fromstring(xml_text)
    if name is None:
        node = root.find(".//Points/DataArray")
    else:
        node = next(a for a in root.iter("DataArray") if a.get("Name") == name)
    return [float(v) for v in node.text.split()]


class ParaViewFrames(unittest.TestCase):
    def test_replay_vtu_every_works_with_the_reduced_step(self):
        # The default config's contact step keeps no full displacement field; the pressure
        # map's reduced step (fe.step: reduced) writes frames from its U v.
        out = os.path.join(ARGS.work, "replay_vtu")
        config = os.path.join(ARGS.work, "reduced.yaml")
        with open(src("config/bridge/default.yaml")) as f:
            text = f.read()
        with open(config, "w") as f:
            f.write(text.replace("step: contact", "step: reduced"))
        status, text = sedbridge("replay", src("config/bridge/example_press.log"), "--config", config, "--out", out,
                                 "--vtu-every", "100", "--no-plots", "--quiet")
        self.assertEqual(status, 0, text)
        self.assertIn("reduced linear step", text)
        with open(os.path.join(out, "frames.pvd")) as f:
            pvd = f.read()
        self.assertIn("timestep = time since the first scan [s]", pvd)
        frames = sorted(n for n in os.listdir(out) if n.endswith(".vtu"))
        self.assertEqual(frames, ["frame_000000.vtu", "frame_000100.vtu", "frame_000200.vtu"])
        texts = [open(os.path.join(out, n)).read() for n in frames]
        # Reference points in every frame; the deformation lives in displacement_mm only.
        self.assertEqual(data_array(texts[0], None), data_array(texts[1], None))
        peak = max(abs(v) for v in data_array(texts[1], "displacement_mm"))
        self.assertGreater(peak, 1e-3, "the pressed frame must carry a displacement [mm]")
        self.assertLess(peak, 5.0)
        self.assertIn('Name="tissue_0_epidermis"', texts[1])
        self.assertGreater(max(data_array(texts[1], "merkel_sed_Pa")), 0)



class PressPointsAtWhatItWrote(unittest.TestCase):
    """`press` names frames.pvd only when the scene wrote VTU frames (outputs.vtu_every > 0)."""

    def press(self, vtu_every):
        scene = os.path.join(ARGS.work, f"press_vtu{vtu_every}.yaml")
        with open(scene, "w") as f:
            f.write("model: B_coarse\nelasticity: linear\ndynamics: {integrator: quasi_static, steps: 2}\n"
                    "bone: {mode: fixed}\ncontact:\n  objects:\n    - {shape: plane, rpy_deg: [180, 0, 0], "
                    "position_mm: [0, 0, 0], motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, "
                    "{t_s: 1, offset_mm: [0, 0, -0.5]}]}}\n"
                    f"outputs: {{merkel_sed: true, vtu_every: {vtu_every}}}\n")
        out = os.path.join(ARGS.work, f"press_vtu{vtu_every}")
        status, text = sedbridge("press", "--scene", scene, "--out", out, "--no-plots", "--quiet")
        self.assertEqual(status, 0, text)
        return out, text

    def test_no_frames_no_pvd_hint(self):
        out, text = self.press(0)
        self.assertNotIn("frames.pvd", text)
        self.assertFalse(os.path.exists(os.path.join(out, "frames.pvd")))

    def test_frames_and_the_hint(self):
        out, text = self.press(1)
        self.assertIn("frames.pvd in ParaView", text)
        self.assertTrue(os.path.exists(os.path.join(out, "frames.pvd")))

if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--sedbridge", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    ARGS, rest = p.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)

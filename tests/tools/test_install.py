#!/usr/bin/env python3
"""`cmake --install` gives a tree that runs outside the source: installs into a temporary
prefix, runs the installed binary's --help and a replay from an unrelated folder, moves the
prefix and runs again, and reads the replay's log with the installed Python package.

  test_install.py --cmake cmake --build-dir build --work DIR
"""

import argparse
import os
import shutil
import subprocess
import sys
import unittest

ARGS = None


def env_without_root(**extra):
    env = dict(os.environ)
    env.pop("SEDBRIDGE_ROOT", None)
    env.pop("LCM_DEFAULT_URL", None)
    env.pop("PYTHONPATH", None)
    env.update(extra)
    return env


class InstalledTree(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(ARGS.work, ignore_errors=True)
        os.makedirs(ARGS.work)
        cls.prefix = os.path.join(ARGS.work, "prefix")
        subprocess.run([ARGS.cmake, "--install", ARGS.build_dir, "--prefix", cls.prefix], check=True,
                       stdout=subprocess.DEVNULL)
        cls.elsewhere = os.path.join(ARGS.work, "elsewhere")  # a cwd with no config/ in it
        os.makedirs(cls.elsewhere)

    def replay(self, prefix, out_name, env=None):
        r = subprocess.run([os.path.join(prefix, "bin", "sedbridge"), "replay", "config/bridge/example_press.log",
                            "--out", out_name, "--no-plots", "--quiet"], cwd=self.elsewhere, capture_output=True,
                           text=True, env=env or env_without_root(), timeout=300)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        return r.stdout

    def test_layout(self):
        share = os.path.join(self.prefix, "share", "sedbridge")
        for path in ["bin/sedbridge", "bin/sedbridge-display-driver", "share/sedbridge/config/bridge/default.yaml", "share/sedbridge/config/models/B.msh",
                     "share/sedbridge/tools/plot_bridge.py", "share/sedbridge/tools/plot_press.py",
                     "share/sedbridge/tools/lcm_spy.sh", "share/sedbridge/python/sedbridge/__init__.py",
                     "share/sedbridge/python/sedbridge_lcm.py", "include/sedbridge/lcmt_display_command.hpp",
                     "share/doc/sedbridge/LICENSE"]:
            self.assertTrue(os.path.exists(os.path.join(self.prefix, path)), path)
        if os.path.exists(os.path.join(ARGS.build_dir, "lcmtypes", "sedbridge_lcmtypes.jar")):
            self.assertTrue(os.path.exists(os.path.join(share, "java", "sedbridge_lcmtypes.jar")))
        self.assertFalse(os.path.exists(os.path.join(share, "tools", "fingertip_generator")))

    def test_help(self):
        r = subprocess.run([os.path.join(self.prefix, "bin", "sedbridge"), "--help"], capture_output=True, text=True,
                           env=env_without_root())
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("replay", r.stdout)

    def test_display_driver_help(self):
        r = subprocess.run([os.path.join(self.prefix, "bin", "sedbridge-display-driver"), "--help"],
                           capture_output=True, text=True, env=env_without_root())
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_leader_press_compare_runs_from_the_installed_tree(self):
        # Its what-if files come with it (its C++ source does not), and it finds the models
        # in the installed tree from an unrelated folder.
        share = os.path.join(self.prefix, "share", "sedbridge", "tools", "leader_press_compare")
        self.assertTrue(os.path.exists(os.path.join(share, "box_corner_yaw.yaml")))
        self.assertFalse(os.path.exists(os.path.join(share, "leader_press_compare.cpp")))
        r = subprocess.run([os.path.join(self.prefix, "bin", "leader_press_compare"), "--model", "B_coarse",
                            "--cache-dir", "", "--force", "0.3", os.path.join(share, "two_spheres_radius.yaml")],
                           cwd=self.elsewhere, capture_output=True, text=True, env=env_without_root(), timeout=240)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertIn("R3.43 and R3.38", r.stdout)

    def test_replay_uses_the_installed_resources_even_after_a_move(self):
        out = self.replay(self.prefix, "out1")
        self.assertIn("with %s/share/sedbridge/config/bridge/default.yaml" % self.prefix, out)
        self.assertTrue(os.path.exists(os.path.join(self.elsewhere, "out1", "bridge.lcmlog")))
        moved = os.path.join(ARGS.work, "moved_prefix")
        shutil.copytree(self.prefix, moved, symlinks=True)
        out = self.replay(moved, "out2")
        self.assertIn("with %s/share/sedbridge/config/bridge/default.yaml" % moved, out)

    def test_sedbridge_root_overrides_the_installed_tree(self):
        root = os.path.join(ARGS.work, "root_copy")
        shutil.copytree(os.path.join(self.prefix, "share", "sedbridge"), root)
        out = self.replay(self.prefix, "out3", env=env_without_root(SEDBRIDGE_ROOT=root))
        self.assertIn("with %s/config/bridge/default.yaml" % root, out)

    def test_installed_python_package_reads_the_replay_log(self):
        self.replay(self.prefix, "out4")
        code = ("import sedbridge_lcm as l, collections; "
                "print(sorted(collections.Counter(e.channel for e in l.EventLog('out4/bridge.lcmlog') "
                "if l.decode(e.data).encode() == e.data).items()))")
        r = subprocess.run([sys.executable, "-c", code], cwd=self.elsewhere, capture_output=True, text=True,
                           env=env_without_root(PYTHONPATH=os.path.join(self.prefix, "share", "sedbridge", "python")))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("('DISPLAY_COMMAND', 303)", r.stdout)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--cmake", default="cmake")
    p.add_argument("--build-dir", required=True)
    p.add_argument("--work", required=True)
    ARGS, rest = p.parse_known_args()
    ARGS.work = os.path.abspath(ARGS.work)
    ARGS.build_dir = os.path.abspath(ARGS.build_dir)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)

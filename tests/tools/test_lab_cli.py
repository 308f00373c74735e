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

    def test_an_empty_flag_is_a_usage_error(self):
        status, out = self.run_live("--lcm-url=")
        self.assertEqual(status, 2, out)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--sedbridge", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    ARGS, rest = p.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)

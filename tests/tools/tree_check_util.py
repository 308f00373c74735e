"""Shared by the tests of the tree checkers (tools/check_*.py): run a checker on a tree, and
write a planted file into a scratch tree."""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))


def run(check, root):
    """Exit status and standard output of tools/<check> on the tree at root."""
    p = subprocess.run([sys.executable, os.path.join(ROOT, "tools", check), root], capture_output=True, text=True)
    return p.returncode, p.stdout


def write(root, path, text):
    full = os.path.join(root, path)
    os.makedirs(os.path.dirname(full), exist_ok=True)
    with open(full, "w") as f:
        f.write(text)

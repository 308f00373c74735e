"""The command line the tree checkers share (tools/check_*.py): ROOT from argv or the
repository, every finding on its own line, exit 1 with a summary when there is one."""
import os
import sys


def main(violations, failure_summary, success_line):
    """violations(root) -> list of lines; failure_summary takes the count (%d)."""
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    found = violations(root)
    for v in found:
        print(v)
    if found:
        print(failure_summary % len(found))
        return 1
    print(success_line)
    return 0

#!/usr/bin/env python3
"""tools/check_code_size.py passes on the tree and fails on a tree with a long file or function."""
import sys
import tempfile

from tree_check_util import ROOT, write
from tree_check_util import run as run_check


def run(root):
    return run_check("check_code_size.py", root)


def function(name, body_lines):
    return "int %s(int x) {\n%s  return x;\n}\n" % (name, "  x += 1;  // { not a brace\n" * body_lines)


def main():
    rc, out = run(ROOT)
    assert rc == 0, "the tree is over the limits:\n" + out
    with tempfile.TemporaryDirectory() as t:
        # Within: a function of 150 lines (signature, 147 + 1 body lines, brace), a long class.
        write(t, "src/fem/ok.cpp", "namespace a {\n" + function("Fits", 147) + "}  // namespace a\n")
        write(t, "src/fem/ok.h", "struct Big {\n" + "  int x;\n" * 200 + "};\n")
        rc, out = run(t)
        assert rc == 0, out
        write(t, "sensors/bad.cpp", "namespace b {\nconst char* s = \"}\";\n" + function("TooLong", 148) + "}\n")
        write(t, "display/long.h", "// a line\n" * 801)
        write(t, "tests/ignored.cpp", function("TestsAreNotChecked", 400))
        rc, out = run(t)
        assert rc == 1, out
        assert "sensors/bad.cpp:3: a function of 151 lines" in out, out
        assert "display/long.h: 801 lines" in out, out
        assert out.count("\n") == 3, out  # two excesses and the summary
    print("code size check: passes on the tree, fails on a 151-line function and an 801-line file")
    return 0


if __name__ == "__main__":
    sys.exit(main())

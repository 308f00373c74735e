#!/usr/bin/env python3
"""tools/check_include_graph.py passes on the tree and fails on a tree that breaks its rules."""
import os
import sys
import tempfile

from tree_check_util import ROOT, write
from tree_check_util import run as run_check


def run(root):
    return run_check("check_include_graph.py", root)


def main():
    rc, out = run(ROOT)
    assert rc == 0, "the tree breaks the include rule:\n" + out

    with tempfile.TemporaryDirectory() as t:
        for stage in ("common", "fem", "scene", "contact", "bridge", "lcm", "fidelity", "app"):
            os.makedirs(os.path.join(t, "src", stage))
        write(t, "sensors/ok.cpp", '#include "sensors/scan.h"\n#include "common/yaml_reader.h"\n#include <vector>\n')
        write(t, "display/ok.h", '#include "display/sed_field.h"\n#include "sedbridge/lcmt_display_command.hpp"\n')
        write(t, "src/contact/ok.cpp", '#include "contact/fit.h"\n#include "scene/fingertip_compliance.h"\n'
                                       '#include "sensors/contact_primitive.h"\n')
        write(t, "src/bridge/ok.cpp", '#include "contact/contact_stage.h"\n#include "lcm/lcm_publisher.h"\n')
        write(t, "src/lcm/ok.cpp", '#include "contact/contact_estimate.h"\n')
        write(t, "src/app/ok.cpp", '#include "fidelity/fidelity_benchmark.h"\n#include "bridge/replay.h"\n')
        write(t, "src/fidelity/ok.cpp", '#include "contact/contact_object.h"\n#include "bridge/replay.h"\n')
        rc, out = run(t)
        assert rc == 0, out
        write(t, "src/contact/bad.cpp", '#include "bridge/pad_registration.h"\n#include "lcm/lcm_publisher.h"\n')
        write(t, "src/lcm/bad.h", '#include "bridge/fe_step.h"\n')
        write(t, "src/bridge/bad.h", '#include "app/command.h"\n')
        write(t, "sensors/simulated/bad.h", '#include "fem/tet_mesh.h"\n')
        write(t, "display/bad.cpp", '  #  include "lcm/lcm_publisher.h"\n')
        write(t, "src/common/bad.h", '#include "bridge/replay.h"\n')
        write(t, "src/bridge/bad.cpp", '#include "src/fidelity/fidelity_case.h"\n')
        rc, out = run(t)
        assert rc == 1, out
        for where in ("sensors/simulated/bad.h:1", "display/bad.cpp:1", "src/common/bad.h:1", "src/contact/bad.cpp:1",
                      "src/contact/bad.cpp:2", "src/lcm/bad.h:1", "src/bridge/bad.h:1", "src/bridge/bad.cpp:1"):
            assert where in out, where + " not reported:\n" + out
        assert out.count("includes src/") == 8, out
    print("include graph check: passes on the tree, fails on 8 planted arrows")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""The project's studies as manifests for tools/study.py (docs/lab-tools.md#studies).

usage: study.py make fidelity-random [--seeds 1-9] [--presses 30] [--ranges rig|wide] --manifest FILE
       study.py make accuracy-cost [--quick] [--reference DIR] --manifest FILE
       study.py make ccx-references [--models A_pad,A,A_coarse] [--elements C3D10] [--material-law neohooke]
                                    [--increments 25] [--threads 1] [--extra "ARGS"] [--timeout-h 6] --manifest FILE

fidelity-random: one case a seed of `sedbridge fidelity --synthetic --random N --seed S`
  (docs/bridge-fidelity.md); gathered into results.csv (every fidelity.csv) and
  tools/fidelity_envelope.py's tables and envelope.png.
accuracy-cost: one `sedbridge press` a configuration of tools/accuracy_cost_study.py, its scene
  written to SCENES beside the manifest; with --reference, gathered by accuracy_cost_study.py
  --rescore into DIR/accuracy_cost/study.csv and pareto.png (times: the cases' wall seconds).
ccx-references: one tools/ccx/run_reference.py a model and element (needs `ccx` on the workers;
  hours a case in C3D10); gathered by tools/ccx/compare_paths.py, the first model the reference.
"""
import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, ".."))


def seeds_arg(text):
    """'1-9' or '1,3,10-12' -> [1, ..., 9]."""
    out = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        out += list(range(int(lo), int(hi or lo) + 1))
    return out


def write_manifest(path, cases, gather=None, note=""):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        if note:
            f.write(f"# {note}\n")
        for c in cases:
            f.write(json.dumps(c) + "\n")
        if gather:
            f.write(json.dumps({"gather": gather}) + "\n")
    print(f"wrote {path}: {len(cases)} cases")


def fidelity_random(a):
    extra = ["--random-ranges", a.ranges] if a.ranges != "rig" else []
    prefix = "seed" if a.ranges == "rig" else f"{a.ranges}_seed"
    cases = [dict(name=f"{prefix}_{s}", timeout_s=1800,
                  command=["{sedbridge}", "fidelity", "--synthetic", "--random", str(a.presses), "--seed", str(s)]
                  + extra + ["--no-plots", "--out", "{out}"]) for s in seeds_arg(a.seeds)]
    gather = dict(csv="fidelity.csv",
                  command=["{python}", "{repo}/tools/fidelity_envelope.py", "--plot", "{study}/envelope.png", "{cases_ok}"])
    write_manifest(a.manifest, cases, gather, f"fidelity random sets: seeds {a.seeds}, {a.presses} presses each, "
                                              f"ranges {a.ranges}")


def accuracy_cost(a):
    sys.path.insert(0, HERE)
    import accuracy_cost_study as acs
    scenes = os.path.join(os.path.dirname(os.path.abspath(a.manifest)), "accuracy_cost_scenes")
    os.makedirs(scenes, exist_ok=True)
    cases = []
    for name, kw in acs.configurations(a.quick):
        with open(os.path.join(scenes, name + ".yaml"), "w") as f:
            f.write(acs.scene_yaml(**kw))
        model = kw.get("model", "B")
        cases.append(dict(name=name, timeout_s=3600,
                          command=["{sedbridge}", "press", "--scene", f"{{manifest}}/accuracy_cost_scenes/{name}.yaml",
                                   "--out", "{out}", "--no-plots", "--quiet"],
                          inputs=[f"{{repo}}/config/models/{model}.yaml", f"{{repo}}/config/models/{model}.msh"]))
    gather = None
    if a.reference:
        gather = dict(command=["{python}", "{repo}/tools/accuracy_cost_study.py", "--rescore",
                               "--reference", os.path.abspath(a.reference), "--runs", "{study}/cases",
                               "--times", "{study}/summary.csv", "--out", "{study}/accuracy_cost"]
                      + (["--quick"] if a.quick else []))
    write_manifest(a.manifest, cases, gather, "accuracy-cost study (tools/accuracy_cost_study.py's configurations)"
                   + ("" if a.reference else "; no --reference: not gathered"))


def ccx_references(a):
    ccx_scripts = [f"{{repo}}/tools/ccx/{s}.py" for s in ("export_deck", "fingertip", "read_results")]
    cases = []
    for model in a.models.split(","):
        for element in a.elements.split(","):
            name = f"{os.path.splitext(os.path.basename(model))[0]}_{element}_{a.material_law}"
            yaml = model if model.endswith(".yaml") else f"{{repo}}/config/models/{model}.yaml"
            cases.append(dict(name=name, timeout_s=int(a.timeout_h * 3600),
                              command=["{python}", "{repo}/tools/ccx/run_reference.py", "--model", model,
                                       "--element", element, "--material-law", a.material_law,
                                       "--increments", str(a.increments), "--threads", str(a.threads)]
                              + a.extra.split() + ["--no-plots", "--out", "{out}"],
                              env={"OMP_NUM_THREADS": str(a.threads)},
                              inputs=ccx_scripts + [yaml, yaml[:-len(".yaml")] + ".msh"]))
    gather = dict(command=["{python}", "{repo}/tools/ccx/compare_paths.py", "{cases_ok}",
                           "--csv", "{study}/compare_paths.csv"])
    write_manifest(a.manifest, cases, gather, "CalculiX references (needs ccx on every worker)")


def main(argv):
    ap = argparse.ArgumentParser(prog="study.py make", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="study", required=True)
    f = sub.add_parser("fidelity-random", help="sedbridge fidelity --synthetic --random N, one case a seed")
    f.add_argument("--seeds", default="1-9")
    f.add_argument("--presses", type=int, default=30)
    f.add_argument("--ranges", choices=("rig", "wide"), default="rig")
    c = sub.add_parser("accuracy-cost", help="tools/accuracy_cost_study.py's configurations, one press each")
    c.add_argument("--quick", action="store_true")
    c.add_argument("--reference", help="the reference run folder (tools/ccx/run_reference.py) for the gather step")
    r = sub.add_parser("ccx-references", help="tools/ccx/run_reference.py, one case a model and element")
    r.add_argument("--models", default="A_pad,A,A_coarse", help="names under config/models or YAML paths; first: "
                                                               "compare_paths' reference")
    r.add_argument("--elements", default="C3D10")
    r.add_argument("--material-law", default="neohooke", choices=("elastic", "neohooke"))
    r.add_argument("--increments", type=int, default=25)
    r.add_argument("--threads", type=int, default=1)
    r.add_argument("--extra", default="", help="more run_reference.py arguments, e.g. \"--depth-mm 1.76\"")
    r.add_argument("--timeout-h", type=float, default=6.0)
    for p in (f, c, r):
        p.add_argument("--manifest", required=True, help="the JSON-lines file to write")
    a = ap.parse_args(argv)
    dict(fidelity_random=fidelity_random, accuracy_cost=accuracy_cost,
         ccx_references=ccx_references)[a.study.replace("-", "_")](a)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

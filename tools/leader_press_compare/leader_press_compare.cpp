// leader_press_compare: presses a reference object and candidate objects on the leader's
// fingertip model (the compliance method's penalty contact, linear quasi-static, bone fixed,
// as the fidelity benchmark's truth) to one normal force, and scores each candidate's Merkel
// SED map against the reference's with the benchmark's metrics (fidelity::CompareMerkelMaps).
// It answers "would the leader feel the difference?" for objects the follower's sensor cannot
// tell apart: a cube corner turned about its diagonal, a sphere read a little large.
//
//   leader_press_compare [--model B] [--force 0.5] [--cache-dir out/cache] [--node-contact]
//                        [--csv FILE] [--maps FILE] FILE.yaml
// (--maps: every press's Merkel map, for tools/plot_leader_press_compare.py)
//
// FILE.yaml (objects as in scenes, config/scenes/README.md; pad frame, touching at z = 0):
//   force_N: 0.191                 # optional, --force overrides
//   reference: [{shape: box, size_mm: [10, 10, 10], rpy_deg: [45, 35.264, 0], position_mm: [1, -1, 8.660]}]
//   candidates:
//     - {name: "turned 30 deg", objects: [{shape: box, ...}]}
// Exit status: 0 when every press reached the force, 1 when one did not, 2 for bad input.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/contact_object.h"
#include "common/config_error.h"
#include "common/geometry/rigid_object.h"
#include "common/yaml_reader.h"
#include "fidelity/fidelity_benchmark.h"
#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"

namespace {

using namespace sedbridge;

constexpr const char* kUsage =
    "usage: leader_press_compare [options] FILE.yaml\n"
    "\n"
    "Presses the file's reference objects and each candidate's objects on the leader's\n"
    "fingertip model to one normal force and compares each candidate's Merkel-layer SED with\n"
    "the reference's: peak ratio, relative L2, peak offset and peak-region offset, as the\n"
    "fidelity benchmark scores the bridge against its truth.\n"
    "\n"
    "options:\n"
    "  --model NAME      leader fingertip model (default: B)\n"
    "  --force N         normal force [N] (default: the file's force_N)\n"
    "  --cache-dir DIR   compliance precompute cache (default: out/cache; \"\" = none)\n"
    "  --node-contact    press on the skin's nodes only, not its faces too\n"
    "  --csv FILE        also write the table as CSV\n"
    "  --maps FILE       write every press's Merkel-layer SED map as CSV (x_mm, y_mm, z_mm in the\n"
    "                    pad frame, then one column per press [Pa]); plot it side by side:\n"
    "                    /usr/bin/python3 tools/plot_leader_press_compare.py FILE\n"
    "  --help            show this help\n"
    "\n"
    "FILE.yaml:\n"
    "  force_N: 0.191\n"
    "  reference: [{shape: box, size_mm: [10, 10, 10], rpy_deg: [45, 35.264, 0], position_mm: [1, -1, 8.660]}]\n"
    "  candidates:\n"
    "    - {name: turned 30 deg, objects: [{shape: box, size_mm: [10, 10, 10], rpy_deg: [45, 35.264, 30], position_mm: [1, -1, 8.660]}]}\n"
    "objects as in scene files (pad frame, mm, degrees); each set is pushed along -z until\n"
    "its total normal force is the force.\n"
    "\n"
    "exit status: 0 every press reached the force, 1 one did not, 2 bad input\n";

struct Candidate {
  std::string name;
  std::vector<geometry::RigidObject> objects;
};

struct Row {
  std::string name, status;
  double force_N = 0, peak_Pa = 0;
  bool reached = false;
  fidelity::MethodError error;
  bool within() const { return fidelity::WithinTargets(error); }
};

}  // namespace

int main(int argc, char** argv) {
  std::string model_name = "B", cache_dir = "out/cache", csv_path, maps_path, file;
  double force_N = -1;
  bool face_contact = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* what) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "leader_press_compare: %s needs a value\n", what);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--model") {
      model_name = value("--model");
    } else if (a == "--force") {
      const std::string v = value("--force");
      char* end = nullptr;
      force_N = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !(force_N > 0)) {
        std::fprintf(stderr, "leader_press_compare: --force: not a positive number: '%s'\n", v.c_str());
        return 2;
      }
    } else if (a == "--cache-dir") {
      cache_dir = value("--cache-dir");
    } else if (a == "--node-contact") {
      face_contact = false;
    } else if (a == "--csv") {
      csv_path = value("--csv");
    } else if (a == "--maps") {
      maps_path = value("--maps");
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "leader_press_compare: unknown option '%s' (--help)\n", a.c_str());
      return 2;
    } else if (file.empty()) {
      file = a;
    } else {
      std::fprintf(stderr, "leader_press_compare: one FILE.yaml, got '%s' too\n", a.c_str());
      return 2;
    }
  }
  if (file.empty()) {
    std::fputs(kUsage, stderr);
    return 2;
  }

  std::vector<geometry::RigidObject> reference;
  std::vector<Candidate> candidates;
  try {
    const config::YamlDocument doc = config::LoadYamlFile(file);
    config::MapReader root(doc.root, doc.file);
    const double file_force_N = root.Optional<double>("force_N", -1);
    if (force_N <= 0) force_N = file_force_N;
    if (!(force_N > 0)) root.Fail("needs force_N > 0 (or --force)");
    reference = geometry::ParseRigidObjects(root, "reference");
    if (reference.empty()) root.Fail(root.Node("reference"), "reference: needs at least one object");
    const YAML::Node list = root.Node("candidates");
    if (!list.IsSequence() || list.size() == 0) root.Fail(list, "candidates: needs a list of {name, objects}");
    for (const YAML::Node& item : list) {
      config::MapReader reader(item, doc.file);
      Candidate c;
      c.name = reader.Required<std::string>("name");
      c.objects = geometry::ParseRigidObjects(reader, "objects");
      if (c.objects.empty()) reader.Fail(reader.Node("objects"), "objects: needs at least one object");
      reader.Finish();
      candidates.push_back(std::move(c));
    }
    root.Finish();
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "leader_press_compare: %s\n", e.what());
    return 2;
  }

  try {
    std::fprintf(stderr, "leader_press_compare: model %s, %.4g N, %zu candidates; building the leader's compliance ...\n",
                 model_name.c_str(), force_N, candidates.size());
    const model::FingertipModel model = model::LoadFingertipModel(model_name);
    scene::FingertipCompliance leader(model, contact::LeaderComplianceOptions(cache_dir, face_contact));
    const scene::PressToForceOptions options;  // the benchmark truth's: the method's own tolerances
    auto press = [&](const std::string& name, const std::vector<geometry::RigidObject>& objects, Eigen::VectorXd* sed) {
      leader.ResetWarmStart();
      const scene::PressToForceResult r = leader.PressToForce(objects, force_N, options);
      Row row;
      row.name = name;
      row.reached = contact::PressAnswered(r, leader);
      row.status = row.reached ? "reached" : scene::ToString(r.status);
      row.force_N = std::abs(r.force_N) < 1e-9 ? 0.0 : r.force_N;  // no contact: 0, not a round-off's -0.0000
      *sed = leader.sed_Pa();
      row.peak_Pa = sed->size() > 0 ? sed->maxCoeff() : 0.0;
      return row;
    };
    std::vector<Eigen::VectorXd> maps(candidates.size() + 1);  // the reference's first
    std::vector<Row> rows = {press("reference", reference, &maps[0])};
    const Eigen::Matrix3Xd& pad_mm = leader.merkel_rest_pad_mm();
    rows[0].error = fidelity::CompareMerkelMaps(pad_mm, maps[0], maps[0]);
    for (size_t k = 0; k < candidates.size(); ++k) {
      rows.push_back(press(candidates[k].name, candidates[k].objects, &maps[k + 1]));
      rows.back().error = fidelity::CompareMerkelMaps(pad_mm, maps[k + 1], maps[0]);
    }
    std::printf("%-28s %-12s %8s %10s %6s %6s %7s %9s %s\n", "objects", "press", "F_N", "peak_Pa", "ratio", "L2",
                "off_mm", "region_mm", "within");
    bool all_reached = true;
    for (const Row& r : rows) {
      all_reached = all_reached && r.reached;
      std::printf("%-28s %-12s %8.4f %10.1f %6.3f %6.3f %7.2f %9.2f %s\n", r.name.c_str(), r.status.c_str(), r.force_N,
                  r.peak_Pa, r.error.peak_ratio, r.error.rel_l2, r.error.peak_offset_mm, r.error.peak_region_offset_mm,
                  r.within() ? "yes" : "no");
    }
    std::printf("within: the fidelity benchmark's targets against the reference (peak ratio 0.80-1.25, rel. L2 <= 0.25, "
                "peak offset <= 1.0 mm)\n");
    if (!csv_path.empty()) {
      std::ofstream csv(csv_path);
      if (!csv) throw std::runtime_error("cannot write " + csv_path);
      csv << "objects,press,force_N,peak_sed_Pa,peak_ratio,rel_l2,peak_offset_mm,peak_region_offset_mm,within_targets\n";
      for (const Row& r : rows)
        csv << '"' << r.name << "\"," << r.status << ',' << r.force_N << ',' << r.peak_Pa << ',' << r.error.peak_ratio
            << ',' << r.error.rel_l2 << ',' << r.error.peak_offset_mm << ',' << r.error.peak_region_offset_mm << ','
            << (r.within() ? 1 : 0) << '\n';
    }
    if (!maps_path.empty()) {
      std::ofstream out(maps_path);
      if (!out) throw std::runtime_error("cannot write " + maps_path);
      out << "x_mm,y_mm,z_mm";
      for (const Row& r : rows) out << ",\"" << r.name << '"';
      out << '\n';
      for (Eigen::Index v = 0; v < pad_mm.cols(); ++v) {
        out << pad_mm(0, v) << ',' << pad_mm(1, v) << ',' << pad_mm(2, v);
        for (const Eigen::VectorXd& m : maps) out << ',' << (v < m.size() ? m[v] : 0.0);
        out << '\n';
      }
    }
    return all_reached ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "leader_press_compare: %s\n", e.what());
    return 2;
  }
}

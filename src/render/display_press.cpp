#include "render/display_press.h"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <stdexcept>
#include <vector>

#include "render/display_on_leader.h"
#include "render/leader_pad.h"
#include "scene/vtu_writer.h"

namespace sedbridge::render {

DisplayPressResult PressDisplay(scene::FingertipCompliance& leader, const display::DisplayProfile& profile,
                                const Eigen::VectorXd& commands) {
  if (!profile.has_device_model())
    throw std::invalid_argument("display press: " + profile.name + " has no device model (key `device`): " +
                                "no mechanical load on the finger");
  if (commands.size() != Eigen::Index(profile.size()))
    throw std::invalid_argument("display press: " + std::to_string(commands.size()) + " commands for " +
                                std::to_string(profile.size()) + " actuators of " + profile.name);
  CheckDisplayFitsLeaderPad(profile, leader);
  const std::unique_ptr<DisplayOnLeader> display = MakeDisplayOnLeader(leader, profile.device);
  DisplayPressResult r;
  r.preload_force_N = display->preload_force_N();
  if (!display->Press(Eigen::VectorXd::Zero(commands.size()), r.preload_sed_Pa))
    throw std::runtime_error("display press: the preload press failed: " + display->error());
  if (!display->Press(commands, r.sed_Pa)) throw std::runtime_error("display press: " + display->error());
  return r;
}

void WriteDisplayPress(const scene::FingertipCompliance& leader, const display::DisplayProfile& profile,
                       const Eigen::VectorXd& commands, const DisplayPressResult& result, const std::string& dir) {
  std::filesystem::create_directories(dir);
  auto open = [&](const std::string& name) {
    std::ofstream out(dir + "/" + name);
    if (!out) throw std::runtime_error("cannot write " + dir + "/" + name);
    out << std::setprecision(8);
    return out;
  };
  const model::FingertipModel& m = leader.model();
  const Eigen::Matrix3Xd& p = leader.merkel_rest_pad_mm();
  const Eigen::VectorXd added = result.sed_Pa - result.preload_sed_Pa;
  // Vertex = Gmsh node tag, as a press writes it, so the two line up.
  const auto write_layer = [&](const std::string& name, const Eigen::VectorXd& sed) {
    auto out = open(name);
    out << "vertex,x_mm,y_mm,z_mm,sed_Pa\n";
    for (size_t v = 0; v < m.merkel_nodes.size(); ++v) {
      const int node = m.merkel_nodes[v];
      out << (m.soft_node_tags.empty() ? size_t(node) : m.soft_node_tags[size_t(node)]) << "," << p(0, Eigen::Index(v))
          << "," << p(1, Eigen::Index(v)) << "," << p(2, Eigen::Index(v)) << "," << sed[Eigen::Index(v)] << "\n";
    }
  };
  write_layer("merkel_sed.csv", result.sed_Pa);
  write_layer("display_added_sed.csv", added);
  {
    auto out = open("display_commands.csv");
    out << "actuator,x_mm,y_mm,command_" << profile.unit << "\n";
    for (size_t i = 0; i < profile.size(); ++i)
      out << i << "," << profile.x_mm[i] << "," << profile.y_mm[i] << "," << commands[Eigen::Index(i)] << "\n";
  }
  {
    auto out = open("display_press.csv");
    out << "model,display,unit,preload_force_N,max_sed_Pa,preload_max_sed_Pa,max_added_sed_Pa\n"
        << m.name << "," << profile.name << "," << profile.unit << "," << result.preload_force_N << ","
        << result.sed_Pa.maxCoeff() << "," << result.preload_sed_Pa.maxCoeff() << "," << added.maxCoeff() << "\n";
  }
  scene::VtuField sed{"merkel_sed_Pa", 1, std::vector<double>(size_t(m.num_soft_nodes()), 0.0)};
  scene::VtuField add{"display_added_sed_Pa", 1, std::vector<double>(size_t(m.num_soft_nodes()), 0.0)};
  for (size_t v = 0; v < m.merkel_nodes.size(); ++v) {
    sed.values[size_t(m.merkel_nodes[v])] = result.sed_Pa[Eigen::Index(v)];
    add.values[size_t(m.merkel_nodes[v])] = added[Eigen::Index(v)];
  }
  const Eigen::VectorXd rest = Eigen::Map<const Eigen::VectorXd>(m.soft.rest_positions_m.data(), m.soft.rest_positions_m.size());
  scene::WriteVtu(dir + "/display_press.vtu", m.soft, rest, {sed, add}, {},
                  {{"preload_force_N", result.preload_force_N}});
}

}  // namespace sedbridge::render

#include "bridge/fe_frame.h"

namespace sedbridge::bridge {

scene::VtuField MerkelSedPointField(int num_nodes, const std::vector<int>& merkel_nodes, const Eigen::VectorXd& sed_Pa) {
  scene::VtuField field{"merkel_sed_Pa", 1, std::vector<double>(size_t(num_nodes), 0.0)};
  for (size_t k = 0; k < merkel_nodes.size() && Eigen::Index(k) < sed_Pa.size(); ++k)
    field.values[size_t(merkel_nodes[k])] = sed_Pa[Eigen::Index(k)];
  return field;
}

}  // namespace sedbridge::bridge

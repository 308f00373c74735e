#include "bridge/leader_model_cache.h"

namespace sedbridge::bridge {

std::shared_ptr<const model::FingertipModel> LeaderModelCache::Model(const std::string& key,
                                                                     const std::function<model::FingertipModel()>& load) {
  auto it = models_.find(key);
  if (it != models_.end()) {
    ++models_shared_;
    return it->second;
  }
  ++models_loaded_;
  return models_.emplace(key, std::make_shared<const model::FingertipModel>(load())).first->second;
}

std::shared_ptr<const fem::ComplianceOperator> LeaderModelCache::Operator(const std::string& key) const {
  auto it = operators_.find(key);
  if (it == operators_.end()) return nullptr;
  ++operators_shared_;
  return it->second;
}

void LeaderModelCache::Remember(const std::string& key, std::shared_ptr<const fem::ComplianceOperator> op) {
  if (op) operators_.emplace(key, std::move(op));
}

}  // namespace sedbridge::bridge

#include "bridge/leader_model_cache.h"

#include "bridge/reduced_linear_fe_step.h"

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

std::shared_ptr<const ReducedLinearPrecompute> LeaderModelCache::Fallback(const std::string& key) const {
  auto it = fallbacks_.find(key);
  if (it == fallbacks_.end()) return nullptr;
  ++fallbacks_shared_;
  return it->second;
}

void LeaderModelCache::RememberFallback(const std::string& key,
                                       std::shared_ptr<const ReducedLinearPrecompute> precompute) {
  fallbacks_[key] = std::move(precompute);
}

}  // namespace sedbridge::bridge

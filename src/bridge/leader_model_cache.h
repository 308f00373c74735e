#pragma once
// The leader models a hand's fingers press on (fe.step contact): the same model named by
// several fingers is loaded once and its compliance precompute (W, G: fem::ComplianceOperator)
// built once; every later finger gets the same const model and operator through a
// shared_ptr and uses them read-only (each finger keeps its own contact state and scratch).
// Memory for each extra finger is then its contact state, not another precompute. The
// pressure-map step's precompute (scene, U) is kept here too, by model and sensor profile.

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "fem/compliance_operator.h"
#include "model/fingertip_model.h"

namespace sedbridge::bridge {

struct ReducedLinearPrecompute;  // bridge/reduced_linear_fe_step.h

class LeaderModelCache {
 public:
  /// The model under `key` (the model's name and what selects its Merkel vertices), loaded
  /// by `load` the first time.
  std::shared_ptr<const model::FingertipModel> Model(const std::string& key,
                                                      const std::function<model::FingertipModel()>& load);
  /// The operator built for `key` (the model's key and the contact's options), null until Remember.
  std::shared_ptr<const fem::ComplianceOperator> Operator(const std::string& key) const;
  void Remember(const std::string& key, std::shared_ptr<const fem::ComplianceOperator> op);

  /// The pressure-map step's precompute (the contact step's fallback, or fe.step reduced)
  /// for `key` (model, preset, sensor profile, Merkel region), null until RememberFallback.
  std::shared_ptr<const ReducedLinearPrecompute> Fallback(const std::string& key) const;
  void RememberFallback(const std::string& key, std::shared_ptr<const ReducedLinearPrecompute> precompute);
  int fallbacks_shared() const { return fallbacks_shared_; }

  int models_loaded() const { return models_loaded_; }
  int models_shared() const { return models_shared_; }
  int operators_shared() const { return operators_shared_; }

 private:
  std::map<std::string, std::shared_ptr<const model::FingertipModel>> models_;
  std::map<std::string, std::shared_ptr<const fem::ComplianceOperator>> operators_;
  int models_loaded_ = 0, models_shared_ = 0;
  mutable int operators_shared_ = 0;
  std::map<std::string, std::shared_ptr<const ReducedLinearPrecompute>> fallbacks_;
  mutable int fallbacks_shared_ = 0;
};

}  // namespace sedbridge::bridge

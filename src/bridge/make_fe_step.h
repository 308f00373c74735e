#pragma once
// The FE step a bridge config asks for (fe.step): the one place that picks a FeStep
// implementation and builds it, for `run`, `replay` and `simulate` alike.

#include <memory>

#include "bridge/bridge_config.h"
#include "bridge/fe_step.h"
#include "bridge/leader_model_cache.h"
#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::bridge {

/// The FE step a config asks for: SceneFeStep (fe.step: scene), ReducedLinearFeStep
/// (fe.step: reduced), both on BridgeSceneDescription(model, preset), or ContactFeStep
/// (fe.step: contact, with the reduced step as its fallback).
/// `full_field`: the step keeps what VTU frames of the whole mesh need (contact step only).
/// `display`: with fe.merkel_region: display, the profile whose sampling footprint bounds
/// the Merkel layer (null: config.display_profile is loaded).
/// `leaders`: fe.step contact's leader model and compliance precompute are taken from it
/// when another finger built them for the same model, Merkel region and contact options,
/// and left there for the next (null: built for this step alone).
std::unique_ptr<FeStep> MakeFeStep(const BridgeConfig& config, const sensors::SensorProfile& profile,
                                   bool full_field = false, const display::DisplayProfile* display = nullptr,
                                   LeaderModelCache* leaders = nullptr);

/// The Merkel vertices `display`'s mapping reads (display::SedToCommandMapping::Reads).
model::MerkelVertexFilter DisplayFootprint(const display::DisplayProfile& display);

}  // namespace sedbridge::bridge

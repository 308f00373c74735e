#include "fidelity/display_fidelity.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "common/resource_path.h"
#include "display/display_kind.h"
#include "display/sed_to_command_mapping.h"
#include "model/fingertip_model.h"
#include "render/display_rendering.h"
#include "render/leader_pad.h"

namespace sedbridge::fidelity {
namespace {

// An electrotactile display in the list: no load on the leader to render, ever.
struct NoMechanicalLoad : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// The shipped display names, for the message refusing an unknown one.
std::string ShippedDisplays() {
  namespace fs = std::filesystem;
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(config::ResolveResource("config/displays"), ec))
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

display::DisplayProfile LoadDisplay(const std::string& name) {
  const std::string path = display::ResolveDisplayProfilePath(name);
  if (!std::filesystem::exists(path))
    throw std::invalid_argument("display fidelity: unknown display '" + name + "' (config/displays has: " +
                                ShippedDisplays() + ")");
  try {
    return display::LoadDisplayProfile(path);
  } catch (const std::exception& e) {
    throw std::invalid_argument("display fidelity: display '" + name + "': " + e.what());
  }
}

display::SedField Field(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& sed_Pa) {
  display::SedField f;
  for (Eigen::Index i = 0; i < pad_mm.cols(); ++i) {
    f.x_mm.push_back(pad_mm(0, i));
    f.y_mm.push_back(pad_mm(1, i));
    f.z_mm.push_back(pad_mm(2, i));
    f.sed_Pa.push_back(sed_Pa[i]);
  }
  return f;
}

double RelL2(const Eigen::VectorXd& a, const Eigen::VectorXd& ref) {
  const double den = ref.norm();
  return den > 0 ? (a - ref).norm() / den : (a.norm() > 0 ? 1.0 : 0.0);
}

// Into [0, max_i]; NaN (a rejected field) as 0, as the safety limiter turns it.
Eigen::VectorXd Clip(const Eigen::VectorXd& u, const Eigen::VectorXd& max) {
  Eigen::VectorXd c(u.size());
  for (Eigen::Index i = 0; i < u.size(); ++i) c[i] = std::isfinite(u[i]) ? std::clamp(u[i], 0.0, max[i]) : 0.0;
  return c;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

const char* RenderingName(DisplayRenderingMethod method) {
  return method == DisplayRenderingMethod::kCurve ? "curve" : "inverse";
}

std::vector<std::string> SplitNameList(const std::string& list, const std::string& what) {
  std::vector<std::string> names;
  size_t start = 0;
  while (true) {
    const size_t comma = list.find(',', start);
    const std::string item = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item.empty()) throw std::invalid_argument(what + ": an empty name in '" + list + "'");
    if (std::find(names.begin(), names.end(), item) != names.end())
      throw std::invalid_argument(what + ": '" + item + "' given twice");
    names.push_back(item);
    if (comma == std::string::npos) return names;
    start = comma + 1;
  }
}

std::vector<DisplayRenderingMethod> ParseRenderings(const std::string& list) {
  std::vector<DisplayRenderingMethod> methods;
  for (const std::string& name : SplitNameList(list, "--rendering")) {
    if (name == "curve")
      methods.push_back(DisplayRenderingMethod::kCurve);
    else if (name == "inverse")
      methods.push_back(DisplayRenderingMethod::kInverse);
    else
      throw std::invalid_argument("--rendering: unknown rendering '" + name + "' (curve, inverse)");
  }
  return methods;
}

// One display: its profile, curve, limits and (when it loads the leader) its rendering.
struct DisplayFidelity::Display {
  display::DisplayProfile profile;
  std::unique_ptr<display::SedToCommandMapping> curve;
  Eigen::VectorXd max;
  std::unique_ptr<render::DisplayRendering> rendering;
};

DisplayFidelity::DisplayFidelity(const std::string& model_name, DisplayFidelityOptions options)
    : options_(std::move(options)) {
  if (options_.displays.empty()) throw std::invalid_argument("display fidelity: no display given");
  if (options_.renderings.empty()) throw std::invalid_argument("display fidelity: no rendering given");
  options_.timing_repeats = std::max(1, options_.timing_repeats);
  // Every profile first: a wrong name is refused before minutes of precompute.
  for (const std::string& name : options_.displays) {
    auto d = std::make_unique<Display>();
    d->profile = LoadDisplay(name);
    d->curve = std::make_unique<display::SedToCommandMapping>(d->profile);
    d->max = render::MaxCommands(d->profile);
    displays_.push_back(std::move(d));
  }
  model_ = std::make_unique<model::FingertipModel>(model::LoadFingertipModel(model_name));
  for (auto& d : displays_) {
    DisplayInfo info;
    info.name = d->profile.name;
    info.actuators = int(d->profile.size());
    if (options_.progress)
      std::fprintf(options_.progress, "display fidelity: %s (%d %s actuators): influence precompute, %d contact solves ...\n",
                   info.name.c_str(), info.actuators, display::ToString(d->profile.kind).c_str(), info.actuators + 1);
    render::DisplayRenderingOptions rendering_options;
    rendering_options.cache_dir = options_.cache_dir;
    rendering_options.fit_reduction = options_.fit_reduction;
    try {
      if (d->profile.kind == display::DisplayKind::kElectrotactile)  // not "yet": it has none
        throw NoMechanicalLoad(d->profile.name + " is electrotactile: no mechanical load on the finger, no SED to "
                               "deliver (replay reads its commands against the SA1 rate estimate)");
      d->rendering = std::make_unique<render::DisplayRendering>(*model_, d->profile, rendering_options);
      info.has_load = true;
      info.precompute_s = d->rendering->precompute_s();
    } catch (const NoMechanicalLoad& e) {
      info.no_load_status = "no mechanical load";
      info.no_load_reason = e.what();
    } catch (const render::DisplayDoesNotFitPad& e) {  // footprints off the leader's pad: file:line:column
      info.no_load_status = "does not fit the pad";
      info.no_load_reason = e.what();
    } catch (const std::invalid_argument& e) {  // no load on the leader for this kind (yet)
      info.no_load_status = "no device load yet";
      info.no_load_reason = e.what();
    } catch (const std::runtime_error& e) {  // a contact solve of the influence failed
      info.no_load_status = "precompute failed";
      info.no_load_reason = e.what();
    }
    if (options_.progress) {
      if (info.has_load)
        std::fprintf(options_.progress, "display fidelity: %s: precompute %.1f s\n", info.name.c_str(), info.precompute_s);
      else
        std::fprintf(options_.progress, "display fidelity: %s: %s (%s)\n", info.name.c_str(),
                     info.no_load_status.c_str(), info.no_load_reason.c_str());
      std::fflush(options_.progress);
    }
    info_.push_back(info);
  }
}

DisplayFidelity::~DisplayFidelity() = default;

std::vector<DisplayFidelityRow> DisplayFidelity::Score(const FidelityRow& row, const FidelityMaps& maps) {
  std::vector<DisplayFidelityRow> rows;
  const Eigen::VectorXd& asked = maps.recon;  // what the bridge hands the display stage
  const display::SedField field = Field(maps.merkel_pad_mm, asked);
  for (size_t k = 0; k < displays_.size(); ++k) {
    Display& d = *displays_[k];
    for (DisplayRenderingMethod method : options_.renderings) {
      DisplayFidelityRow r;
      r.case_name = row.name;
      r.display = d.profile.name;
      r.rendering = RenderingName(method);
      r.actuators = int(d.profile.size());
      r.asked_max_sed_Pa = asked.size() ? asked.maxCoeff() : 0;
      r.truth_max_sed_Pa = row.truth_max_sed_Pa;
      if (!d.rendering) {
        r.status = info_[k].no_load_status;
        rows.push_back(r);
        continue;
      }
      // The SED -> commands step, timed alone; the inverse cold (no warm start from another case).
      Eigen::VectorXd u;
      std::vector<double> ms;
      for (int t = 0; t < options_.timing_repeats; ++t) {
        const auto start = std::chrono::steady_clock::now();
        if (method == DisplayRenderingMethod::kCurve) {
          const std::vector<double> requested = d.curve->Map(field).requested;
          u = Eigen::Map<const Eigen::VectorXd>(requested.data(), Eigen::Index(requested.size()));
        } else {
          d.rendering->renderer().Reset();
          u = d.rendering->Render(asked);
        }
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      }
      r.render_ms = Median(ms);
      u = Clip(u, d.max);
      for (Eigen::Index i = 0; i < u.size(); ++i) {
        r.commands_at_max += d.max[i] > 0 && u[i] >= d.max[i];
        if (d.max[i] > 0) r.max_command_share = std::max(r.max_command_share, u[i] / d.max[i]);
      }
      Eigen::VectorXd delivered;
      if (!d.rendering->Deliver(u, delivered)) {
        r.status = "deliver failed: " + d.rendering->error();
        rows.push_back(r);
        continue;
      }
      r.delivered_max_sed_Pa = delivered.maxCoeff();
      r.vs_asked_rel_l2 = RelL2(delivered, asked);
      r.scored = row.truth_valid;
      r.status = r.scored ? "ok" : "no valid truth";
      if (r.scored) r.delivered = CompareMerkelMaps(maps.merkel_pad_mm, delivered, maps.truth);
      rows.push_back(r);
    }
  }
  return rows;
}

std::vector<DisplayFidelitySummary> SummarizeDisplayFidelity(const std::vector<DisplayFidelityRow>& rows) {
  std::vector<DisplayFidelitySummary> out;
  std::vector<std::vector<const DisplayFidelityRow*>> members;
  for (const DisplayFidelityRow& r : rows) {
    auto it = std::find_if(out.begin(), out.end(),
                           [&](const DisplayFidelitySummary& s) { return s.display == r.display && s.rendering == r.rendering; });
    if (it == out.end()) {
      DisplayFidelitySummary s;
      s.display = r.display;
      s.rendering = r.rendering;
      s.status = r.status;
      out.push_back(s);
      members.emplace_back();
      it = out.end() - 1;
    }
    members[size_t(it - out.begin())].push_back(&r);
  }
  for (size_t k = 0; k < out.size(); ++k) {
    DisplayFidelitySummary& s = out[k];
    std::vector<double> peak, l2, offset, asked, ms;
    for (const DisplayFidelityRow* r : members[k]) {
      ++s.rows;
      if (r->status != s.status) s.status = "mixed";
      s.deliver_failed += r->status.rfind("deliver failed", 0) == 0;
      if (!r->scored) continue;
      ++s.scored;
      s.within_targets += WithinTargets(r->delivered);
      s.commands_at_max += r->commands_at_max;
      peak.push_back(r->delivered.peak_ratio);
      l2.push_back(r->delivered.rel_l2);
      offset.push_back(r->delivered.peak_offset_mm);
      asked.push_back(r->vs_asked_rel_l2);
      ms.push_back(r->render_ms);
    }
    if (s.scored > 0) s.status = "ok";
    s.peak_ratio = Median(peak);
    s.rel_l2 = Median(l2);
    s.peak_offset_mm = Median(offset);
    s.vs_asked_rel_l2 = Median(asked);
    s.render_ms = Median(ms);
  }
  return out;
}

}  // namespace sedbridge::fidelity

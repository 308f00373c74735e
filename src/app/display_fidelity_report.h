#pragma once
// `sedbridge fidelity --display-fidelity`: the display-level rows of each case
// (fidelity/display_fidelity.h) into display_fidelity.csv, and the table printed at the end.

#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "fidelity/display_fidelity.h"

namespace sedbridge::app {

class DisplayFidelityReport {
 public:
  /// Builds every display's rendering (progress to options.progress) and opens OUT/display_fidelity.csv.
  DisplayFidelityReport(const std::string& model_name, fidelity::DisplayFidelityOptions options, const std::string& out);
  /// Renders, delivers and scores one case; its rows go to the CSV at once.
  void Add(const fidelity::FidelityRow& row, const fidelity::FidelityMaps& maps);
  /// The table: medians per display and rendering over the scored cases.
  void Print() const;

 private:
  fidelity::DisplayFidelity fidelity_;
  std::string path_;
  std::ofstream csv_;
  std::vector<fidelity::DisplayFidelityRow> rows_;
};

}  // namespace sedbridge::app

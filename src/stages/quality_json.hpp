// MeshQuality as JSON, for the --report and `partet check --json` (internal header).
#pragma once
#include <nlohmann/json.hpp>

#include "stages/quality.hpp"

namespace partet {

inline nlohmann::json quality_json(const MeshQuality& q) {
  nlohmann::json histogram = nlohmann::json::array();
  double from = 0;
  for (std::size_t i = 0; i < kDihedralBins.size(); ++i) {
    histogram.push_back({{"from_deg", from}, {"to_deg", kDihedralBins[i]}, {"angles", q.dihedral_histogram[i]}});
    from = kDihedralBins[i];
  }
  return {{"tets", q.tets},
          {"amips_avg", q.amips_avg},
          {"amips_p99", q.amips_p99},
          {"amips_max", q.amips_max},
          {"min_dihedral_deg", q.min_dihedral_deg},
          {"max_dihedral_deg", q.max_dihedral_deg},
          {"tets_below_5deg", q.below_5deg},
          {"tets_above_175deg", q.above_175deg},
          {"radius_edge_avg", q.radius_edge_avg},
          {"radius_edge_max", q.radius_edge_max},
          {"tets_radius_edge_above_2", q.radius_edge_above_2},
          {"dihedral_histogram", histogram}};
}

// One line: "AMIPS avg 4.21 p99 8.8 max 44.4; dihedral min 1.81 max 177 deg; ..."
inline std::string quality_line(const MeshQuality& q) {
  char text[320];
  std::snprintf(text, sizeof text,
                "AMIPS avg %.4g p99 %.4g max %.4g; dihedral min %.4g max %.4g deg; radius-edge avg %.4g max %.4g; "
                "tets <5deg %lld, >175deg %lld",
                q.amips_avg, q.amips_p99, q.amips_max, q.min_dihedral_deg, q.max_dihedral_deg, q.radius_edge_avg,
                q.radius_edge_max, static_cast<long long>(q.below_5deg), static_cast<long long>(q.above_175deg));
  return text;
}

}  // namespace partet

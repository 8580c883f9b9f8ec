#include "analysis/core/cloud.hpp"

#include <string>

#include "analysis/core/errors.hpp"

namespace sailshape {

namespace {

template <typename T>
void checkAttributeSize(const std::vector<T>& attribute, const char* name, size_t n_points) {
  if (!attribute.empty() && attribute.size() != n_points)
    throw InvalidInput("[selectPoints] " + std::string(name) + " has " + std::to_string(attribute.size()) +
                       " values for " + std::to_string(n_points) + " points");
}

template <typename T>
void copyAt(const std::vector<T>& from, const std::vector<uint32_t>& indices, std::vector<T>& to) {
  if (from.empty()) return;
  to.reserve(indices.size());
  for (uint32_t i : indices) to.push_back(from[i]);
}

}  // namespace

Cloud selectPoints(const Cloud& cloud, const std::vector<uint32_t>& indices) {
  const size_t n = cloud.size();
  checkAttributeSize(cloud.intensity, "intensity", n);
  checkAttributeSize(cloud.alpha_rad, "alpha_rad", n);
  checkAttributeSize(cloud.beta_rad, "beta_rad", n);
  for (uint32_t i : indices)
    if (i >= n)
      throw InvalidInput("[selectPoints] index " + std::to_string(i) + " out of range (cloud has " + std::to_string(n) +
                         " points)");

  Cloud out;
  copyAt(cloud.points, indices, out.points);
  copyAt(cloud.intensity, indices, out.intensity);
  copyAt(cloud.alpha_rad, indices, out.alpha_rad);
  copyAt(cloud.beta_rad, indices, out.beta_rad);
  out.viewpoint = cloud.viewpoint;
  out.scanner_range_m = cloud.scanner_range_m;
  out.lost_beta_rad = cloud.lost_beta_rad;
  return out;
}

}  // namespace sailshape

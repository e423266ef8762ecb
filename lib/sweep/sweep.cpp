#include "cellmap/sweep/sweep.hpp"

namespace cellmap {

Cloud Sweep::merged() const {
  Cloud all;
  all.reserve(point_count());
  for (const Scan& scan : scans) all += scan.points_C;
  return all;
}

std::size_t Sweep::point_count() const {
  std::size_t n = 0;
  for (const Scan& scan : scans) n += scan.points_C.size();
  return n;
}

}  // namespace cellmap

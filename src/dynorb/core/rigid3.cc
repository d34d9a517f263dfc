#include "dynorb/core/rigid3.h"

#include <algorithm>
#include <cmath>

namespace dynorb {

double RotationAngleRad(const Eigen::Quaterniond& q) {
  const Eigen::Quaterniond n = q.normalized();
  // Robust form: 2*atan2(|v|, |w|) is accurate for small and large angles alike.
  return 2.0 * std::atan2(n.vec().norm(), std::abs(n.w()));
}

}  // namespace dynorb

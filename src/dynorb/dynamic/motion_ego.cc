#include "dynorb/dynamic/motion_ego.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "dynorb/dynamic/fast_cues.h"
#include "dynorb/dynamic/pixel.h"
#include "dynorb/optimization/pose_optimizer.h"

namespace dynorb {
namespace {

Rigid3d FromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d rot;
  cv::cv2eigen(r, rot);
  return Rigid3d(rot, Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)));
}

struct Problem {
  const PinholeCamera* camera;
  cv::Mat k;
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  std::vector<int> cell;  // coverage cell of each point
  int num_cells = 0;
  int occupied = 0;       // cells holding any point
  const EgoMotionOptions* options;

  std::vector<double> Residuals(const Rigid3d& pose) const {
    std::vector<double> res(object.size(), std::numeric_limits<double>::infinity());
    const Eigen::Matrix3d r = pose.rotation.toRotationMatrix();
    for (size_t i = 0; i < object.size(); ++i) {
      const Eigen::Vector3d x = r * Eigen::Vector3d(object[i].x, object[i].y, object[i].z) + pose.translation;
      if (x.z() <= 1e-6) continue;
      const Eigen::Vector2d u = camera->Project(x);
      const double dx = u.x() - image[i].x, dy = u.y() - image[i].y;
      res[i] = std::sqrt(dx * dx + dy * dy);
    }
    return res;
  }

  std::vector<uint8_t> Inliers(const Rigid3d& pose, double gate) const {
    const std::vector<double> res = Residuals(pose);
    std::vector<uint8_t> in(res.size(), 0);
    for (size_t i = 0; i < res.size(); ++i) in[i] = res[i] < gate;
    return in;
  }

  // Fraction of the occupied cells where the hypothesis explains most points (at least 2 and at
  // least half of the cell's points): a motion that fits a few points everywhere does not count.
  double Coverage(const std::vector<uint8_t>& in) const {
    std::vector<int> count(num_cells, 0), total(num_cells, 0);
    for (size_t i = 0; i < in.size(); ++i) {
      count[cell[i]] += in[i];
      ++total[cell[i]];
    }
    int covered = 0;
    for (int c = 0; c < num_cells; ++c) covered += count[c] >= 2 && 2 * count[c] >= total[c];
    return occupied > 0 ? static_cast<double>(covered) / occupied : 0.0;
  }

  // The 3D points and their previous pixels where selected[i] != 0.
  void Select(const std::vector<uint8_t>& selected, std::vector<cv::Point3f>* obj, std::vector<cv::Point2f>* img) const {
    for (size_t i = 0; i < selected.size(); ++i) {
      if (!selected[i]) continue;
      obj->push_back(object[i]);
      img->push_back(image[i]);
    }
  }

  // Refit on the points within `gate`; false when fewer than min_points are. *last_selection:
  // the points of the previous refit of this pose. When the gate selects the same points again,
  // another fit would only continue the previous one (which converged or used its lm_iterations):
  // it is skipped.
  bool Refit(double gate, Rigid3d* pose, int* inliers, std::vector<uint8_t>* last_selection) const {
    std::vector<uint8_t> selected = Inliers(*pose, gate);
    const int count = static_cast<int>(std::count(selected.begin(), selected.end(), uint8_t{1}));
    if (count < options->min_points) return false;
    *inliers = count;
    if (selected == *last_selection) return true;
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (size_t i = 0; i < selected.size(); ++i) {
      if (!selected[i]) continue;
      points.emplace_back(object[i].x, object[i].y, object[i].z);
      pixels.emplace_back(image[i].x, image[i].y);
    }
    *last_selection = std::move(selected);
    // An evenly strided subset is enough for 6 parameters and keeps the cost flat.
    if (options->max_fit_points > 0 && count > options->max_fit_points) {
      const double stride = static_cast<double>(count) / options->max_fit_points;
      for (int j = 0; j < options->max_fit_points; ++j) {
        const size_t from = static_cast<size_t>(j * stride);
        points[j] = points[from];
        pixels[j] = pixels[from];
      }
      points.resize(options->max_fit_points);
      pixels.resize(options->max_fit_points);
    }
    const std::optional<Rigid3d> fit =
        RefinePoseLeastSquares(*camera, std::move(points), pixels, *pose, options->lm_iterations);
    if (!fit) return false;
    *pose = *fit;
    return true;
  }

  // Robust spread (1.4826 × median) of the residuals below `gate`; infinity with too few.
  double Sigma(const Rigid3d& pose, double gate) const {
    std::vector<double> in;
    for (double r : Residuals(pose)) {
      if (r < gate) in.push_back(r);
    }
    if (static_cast<int>(in.size()) < options->min_points) return std::numeric_limits<double>::infinity();
    std::nth_element(in.begin(), in.begin() + in.size() / 2, in.end());
    return 1.4826 * in[in.size() / 2];
  }

  // Shrinking-gate refinement, then the adaptive gate; false when too few points support the
  // estimate, or when `abandon` (if set) is true for the pose after the first gate's refit.
  // *sigma: the final spread.
  bool Refine(Rigid3d* pose, int* inliers, double* sigma,
              const std::function<bool(const Rigid3d&)>& abandon = {}) const {
    *inliers = 0;
    double last_gate = options->ransac_px;
    bool shrunk = true;
    std::vector<uint8_t> last_selection;
    for (size_t g = 0; g < options->gates_px.size(); ++g) {
      const double gate = options->gates_px[g];
      if (!Refit(gate, pose, inliers, &last_selection)) {
        shrunk = false;
        break;
      }
      if (g == 0 && abandon && abandon(*pose)) return false;
      last_gate = gate;
    }
    if (*inliers == 0) return false;
    for (int it = 0; shrunk && it < options->adaptive_iterations; ++it) {
      const double spread = Sigma(*pose, last_gate);
      if (!std::isfinite(spread)) break;
      const double gate = std::clamp(options->gate_sigmas * spread, options->min_gate_px, last_gate);
      if (!Refit(gate, pose, inliers, &last_selection)) break;
      last_gate = gate;
    }
    *sigma = Sigma(*pose, last_gate);
    return true;
  }

  // PnP-RANSAC on the points with use[i] != 0.
  bool Ransac(const std::vector<uint8_t>& use, Rigid3d* pose) const {
    std::vector<cv::Point3f> obj;
    std::vector<cv::Point2f> img;
    Select(use, &obj, &img);
    if (static_cast<int>(obj.size()) < options->min_points) return false;
    cv::Mat rvec, tvec;
    std::vector<int> inliers;
    cv::setRNGSeed(12345);
    const bool ok = cv::solvePnPRansac(obj, img, k, cv::noArray(), rvec, tvec, false, options->ransac_iterations,
                                       static_cast<float>(options->ransac_px), 0.99, inliers, cv::SOLVEPNP_EPNP);
    if (!ok || static_cast<int>(inliers.size()) < options->min_points) return false;
    *pose = FromRvecTvec(rvec, tvec);
    return true;
  }
};

}  // namespace

std::vector<uint8_t> EgoMotionVoters(const std::vector<uint8_t>& valid,
                                     const std::vector<cv::Point2f>& p1,
                                     const cv::Mat& previous_mask, double max_fraction) {
  std::vector<uint8_t> voters = valid;
  if (previous_mask.empty()) return voters;
  int tracked = 0, skipped = 0;
  for (size_t i = 0; i < voters.size(); ++i) {
    if (!voters[i]) continue;
    ++tracked;
    if (previous_mask.at<uint8_t>(NearestPixel(p1[i], previous_mask.size())))
      voters[i] = 0, ++skipped;
  }
  return skipped > max_fraction * tracked ? valid : voters;
}

EgoMotionResult EstimateEgoMotion(const PinholeCamera& camera, const std::vector<cv::Point2f>& p1,
                                  const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid,
                                  const cv::Mat& depth_cur, const std::vector<Rigid3d>& seeds_prev_from_cur,
                                  const EgoMotionOptions& options) {
  EgoMotionResult result;
  if (!options.refine && !seeds_prev_from_cur.empty()) {
    result.ok = true;
    result.seed_index = 0;
    result.prev_from_cur = seeds_prev_from_cur[0];
    return result;
  }
  Problem problem;
  problem.camera = &camera;
  problem.options = &options;
  problem.k = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  problem.num_cells = options.grid_cols * options.grid_rows;
  std::vector<uint8_t> occupied(problem.num_cells, 0);
  // 3D points away from depth edges (the edge depth is ambiguous).
  for (size_t i = 0; i < p1.size(); ++i) {
    if (!valid[i]) continue;
    const DepthSample z = SampleDepth(depth_cur, p2[i], options.max_depth_m);
    if (z.center <= 0.f || z.max - z.min > 0.05f + 0.08f * z.center) continue;
    const Eigen::Vector3d x = camera.Unproject(Eigen::Vector2d(p2[i].x, p2[i].y), z.center);
    problem.object.emplace_back(static_cast<float>(x.x()), static_cast<float>(x.y()), static_cast<float>(x.z()));
    problem.image.push_back(p1[i]);
    const int cx = std::clamp(static_cast<int>(p2[i].x * options.grid_cols / camera.width), 0, options.grid_cols - 1);
    const int cy = std::clamp(static_cast<int>(p2[i].y * options.grid_rows / camera.height), 0, options.grid_rows - 1);
    problem.cell.push_back(cy * options.grid_cols + cx);
  }
  {
    std::vector<int> count(problem.num_cells, 0);
    for (int c : problem.cell) ++count[c];
    for (int c : count) problem.occupied += c >= 2;
  }
  const double wide_gate = options.gates_px.empty() ? options.ransac_px : options.gates_px.back();
  // Seed hypotheses (priority order) and two RANSAC hypotheses: the dominant motion and the
  // dominant motion of its outliers.
  struct Hypothesis {
    Rigid3d pose;
    int inliers = 0;
    double coverage = 0.0;
    int seed = -1;
    double sigma = 0.0;
  };
  std::vector<Hypothesis> hypotheses;
  const int num_predictions = static_cast<int>(seeds_prev_from_cur.size());
  const int identity_seed = options.try_identity ? num_predictions : -1;
  // Is `pose` within duplicate_seed_m / duplicate_seed_rad of a hypothesis refined already?
  auto near_refined = [&](const Rigid3d& pose) {
    return std::any_of(hypotheses.begin(), hypotheses.end(), [&](const Hypothesis& h) {
      return (h.pose.translation - pose.translation).norm() < options.duplicate_seed_m &&
             RotationAngleRad(h.pose.rotation * pose.rotation.conjugate()) <
                 options.duplicate_seed_rad;
    });
  };
  auto refine_seed = [&](const Rigid3d& start, int seed,
                         const std::function<bool(const Rigid3d&)>& abandon = {}) {
    Hypothesis h;
    h.pose = start;
    h.seed = seed;
    if (problem.Refine(&h.pose, &h.inliers, &h.sigma, abandon)) hypotheses.push_back(h);
  };
  // Scores every hypothesis at one gate: the best-fitting hypothesis sets the noise level.
  double score_gate = wide_gate, best_coverage = 0.0;
  int best_inliers = 0;
  auto score_all = [&]() {
    double min_sigma = std::numeric_limits<double>::infinity();
    for (const Hypothesis& h : hypotheses) min_sigma = std::min(min_sigma, h.sigma);
    score_gate = std::isfinite(min_sigma)
                     ? std::clamp(options.gate_sigmas * min_sigma, options.score_min_gate_px, wide_gate)
                     : wide_gate;
    best_coverage = 0.0;
    best_inliers = 0;
    for (Hypothesis& h : hypotheses) {
      const std::vector<uint8_t> in = problem.Inliers(h.pose, score_gate);
      h.coverage = problem.Coverage(in);
      h.inliers = static_cast<int>(std::count(in.begin(), in.end(), uint8_t{1}));
      best_coverage = std::max(best_coverage, h.coverage);
      best_inliers = std::max(best_inliers, h.inliers);
    }
  };
  // A prediction next to one already refined (the tracker's and the filter's own
  // constant-velocity models usually agree) would refine to the same pose; so would one that
  // lands next to it after its first refit (abandon_duplicate_predictions).
  const std::function<bool(const Rigid3d&)> abandon_prediction =
      options.abandon_duplicate_predictions ? near_refined : std::function<bool(const Rigid3d&)>();
  for (int s = 0; s < num_predictions; ++s) {
    const Rigid3d& start = seeds_prev_from_cur[s];
    if (!near_refined(start)) refine_seed(start, s, abandon_prediction);
  }
  score_all();
  // A prediction that fits to the noise floor (3 sigmas within skip_search_gate_px) and covers
  // skip_search_coverage of the cells there needs no search (on real, noisier data the spread may
  // be larger and the search runs).
  const bool search =
      best_coverage < options.skip_search_coverage || score_gate > options.skip_search_gate_px;
  if (search) {
    if (options.try_identity) refine_seed(Rigid3d(), identity_seed);
    std::vector<uint8_t> use(problem.object.size(), 1);
    for (int r = 0; r < 2; ++r) {
      Hypothesis h;
      if (!problem.Ransac(use, &h.pose)) break;
      if (!problem.Refine(&h.pose, &h.inliers, &h.sigma)) break;
      hypotheses.push_back(h);
      // Its own points: within 3 sigmas of its fit (2..2*ransac_px), so that a loosely fitting
      // first hypothesis does not also swallow the second motion's points.
      const double own = std::isfinite(h.sigma)
                             ? std::clamp(options.gate_sigmas * h.sigma, wide_gate, 2.0 * options.ransac_px)
                             : 2.0 * options.ransac_px;
      const std::vector<uint8_t> wide = problem.Inliers(h.pose, own);
      for (size_t i = 0; i < use.size(); ++i) use[i] = use[i] && !wide[i];
    }
    score_all();
  }
  if (hypotheses.empty()) return result;
  // The first seed with nearly the best support wins; otherwise the hypothesis covering most of
  // the image.
  const Hypothesis* chosen = nullptr;
  // Does every hypothesis covering more than `seed` fit at least seed_rigidity_ratio times more loosely?
  auto most_rigid = [&](const Hypothesis& seed) {
    if (options.seed_rigidity_ratio <= 0.0 || !(seed.sigma > 0.0)) return false;
    return std::all_of(hypotheses.begin(), hypotheses.end(), [&](const Hypothesis& h) {
      return h.coverage <= seed.coverage || h.sigma >= options.seed_rigidity_ratio * seed.sigma;
    });
  };
  for (const Hypothesis& h : hypotheses) {
    if (h.seed >= 0 && h.seed != identity_seed && h.coverage >= options.min_seed_coverage &&
        ((h.coverage >= options.seed_coverage_ratio * best_coverage &&
          h.inliers >= options.seed_coverage_ratio * best_inliers) ||
         most_rigid(h))) {
      chosen = &h;
      break;
    }
  }
  if (chosen == nullptr) {
    for (const Hypothesis& h : hypotheses) {
      // Coverage first (the static background is spread over the image), then inliers.
      if (chosen == nullptr || h.coverage > chosen->coverage ||
          (h.coverage == chosen->coverage && h.inliers > chosen->inliers)) {
        chosen = &h;
      }
    }
  }
  result.ok = true;
  result.seed_index = chosen->seed == identity_seed ? -2 : chosen->seed;
  result.sigma_px = chosen->sigma;
  result.gate_px = score_gate;
  result.prev_from_cur = chosen->pose;
  result.num_inliers = chosen->inliers;
  result.coverage = chosen->coverage;
  result.searched = search;
  result.hypotheses = static_cast<int>(hypotheses.size());
  return result;
}

EgoMotionResult EstimateEgoMotionWithPrior(
    const PinholeCamera& camera, const std::vector<cv::Point2f>& p1,
    const std::vector<cv::Point2f>& p2, const std::vector<uint8_t>& valid, const cv::Mat& depth_cur,
    const std::vector<Rigid3d>& seeds_prev_from_cur, const cv::Mat& previous_mask,
    double max_fraction, const EgoMotionOptions& options, bool always) {
  if (always && !previous_mask.empty()) {
    const std::vector<uint8_t> voters = EgoMotionVoters(valid, p1, previous_mask, max_fraction);
    const EgoMotionResult without =
        EstimateEgoMotion(camera, p1, p2, voters, depth_cur, seeds_prev_from_cur, options);
    if (without.ok) return without;
  }
  const EgoMotionResult all =
      EstimateEgoMotion(camera, p1, p2, valid, depth_cur, seeds_prev_from_cur, options);
  if (!all.ok || all.seed_index >= 0 || seeds_prev_from_cur.empty() || previous_mask.empty()) {
    return all;
  }
  const std::vector<uint8_t> voters = EgoMotionVoters(valid, p1, previous_mask, max_fraction);
  if (voters == valid) return all;
  const EgoMotionResult again =
      EstimateEgoMotion(camera, p1, p2, voters, depth_cur, seeds_prev_from_cur, options);
  return again.ok && again.seed_index >= 0 ? again : all;
}

}  // namespace dynorb

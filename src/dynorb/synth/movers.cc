#include "dynorb/synth/movers.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "dynorb/core/angles.h"

namespace dynorb::synth {
namespace {

double Smooth(double f) { return f * f * (3.0 - 2.0 * f); }

Rigid3d Pose(const Eigen::Vector3d& p, double yaw) {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), p);
}

void AppendRigid(const std::vector<DrawQuad>& local, const Rigid3d& world_from_object, int id,
                 std::vector<DrawQuad>* quads) {
  for (DrawQuad q : local) {
    q.origin = world_from_object * q.origin;
    q.axis_u = world_from_object.rotation * q.axis_u;
    q.axis_v = world_from_object.rotation * q.axis_v;
    q.object_id = id;
    quads->push_back(q);
  }
}

}  // namespace

void KeyframePath::Add(double t_s, const Eigen::Vector3d& position, double yaw_rad) {
  const double dist =
      keys_.empty() ? 0.0 : keys_.back().dist + (position - keys_.back().p).head<2>().norm();
  keys_.push_back({t_s, position, yaw_rad, dist});
}

void KeyframePath::Wait(double duration_s) {
  Add(keys_.back().t + duration_s, keys_.back().p, keys_.back().yaw);
}

void KeyframePath::MoveTo(const Eigen::Vector3d& position, double speed_mps, double yaw_rad) {
  const double length = (position - keys_.back().p).norm();
  Add(keys_.back().t + std::max(0.1, length / speed_mps), position, yaw_rad);
}

size_t KeyframePath::Segment(double t) const {
  auto it = std::upper_bound(keys_.begin(), keys_.end(), t,
                             [](double v, const Key& k) { return v < k.t; });
  return static_cast<size_t>(std::max<std::ptrdiff_t>(0, (it - keys_.begin()) - 1));
}

Eigen::Vector3d KeyframePath::Position(double t, bool eased) const {
  if (t <= keys_.front().t) return keys_.front().p;
  if (t >= keys_.back().t) return keys_.back().p;
  const size_t i = Segment(t);
  double f = (t - keys_[i].t) / (keys_[i + 1].t - keys_[i].t);
  if (eased) f = Smooth(f);
  return (1.0 - f) * keys_[i].p + f * keys_[i + 1].p;
}

double KeyframePath::Yaw(double t, bool eased) const {
  if (t <= keys_.front().t) return keys_.front().yaw;
  if (t >= keys_.back().t) return keys_.back().yaw;
  const size_t i = Segment(t);
  double f = (t - keys_[i].t) / (keys_[i + 1].t - keys_[i].t);
  if (eased) f = Smooth(f);
  return (1.0 - f) * keys_[i].yaw + f * keys_[i + 1].yaw;
}

double KeyframePath::Distance(double t) const {
  if (t <= keys_.front().t) return 0.0;
  if (t >= keys_.back().t) return keys_.back().dist;
  const size_t i = Segment(t);
  const double f = (t - keys_[i].t) / (keys_[i + 1].t - keys_[i].t);
  return (1.0 - f) * keys_[i].dist + f * keys_[i + 1].dist;
}

Eigen::Vector2d KeyframePath::Heading(double t) const {
  size_t i = std::min(Segment(t), keys_.size() - 1);
  for (;; --i) {
    if (i + 1 < keys_.size()) {
      const Eigen::Vector2d d = (keys_[i + 1].p - keys_[i].p).head<2>();
      if (d.norm() > 1e-6) return d.normalized();
    }
    if (i == 0) break;
  }
  for (size_t j = 0; j + 1 < keys_.size();
       ++j) {  // not moved yet: the first direction it will take
    const Eigen::Vector2d d = (keys_[j + 1].p - keys_[j].p).head<2>();
    if (d.norm() > 1e-6) return d.normalized();
  }
  return Eigen::Vector2d::UnitX();
}

double KeyframePath::RestSince(double t) const {
  if (keys_.empty()) return t;
  if (t <= keys_.front().t) return keys_.front().t;
  auto rests = [this](size_t i) { return (keys_[i + 1].p - keys_[i].p).norm() < 1e-9; };
  size_t i = Segment(t);
  if (i + 1 >= keys_.size()) {  // After the last key: at rest since it (and any rest before it).
    i = keys_.size() - 1;
  } else if (!rests(i)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  while (i > 0 && rests(i - 1)) --i;
  return keys_[i].t;
}

double KeyframePath::LastRestEnd(double t) const {
  if (keys_.size() < 2 || t <= keys_.front().t) return std::numeric_limits<double>::quiet_NaN();
  auto rests = [this](size_t i) { return (keys_[i + 1].p - keys_[i].p).norm() < 1e-9; };
  size_t i = Segment(t);
  while (i > 0) {
    --i;
    if (rests(i)) return keys_[i + 1].t;
  }
  return keys_.front().t;  // It stood at its first key until it set off.
}

Movers::Movers(const Office& office, bool sitting, int num_people, double duration_s, uint64_t seed,
               std::vector<PersonLook> looks)
    : office_(&office), looks_(std::move(looks)) {
  const Office& o = office;
  for (int i = 0; i < num_people; ++i) {
    std::mt19937_64 rng(seed * 0xBF58476D1CE4E5B9ULL + 101 + i);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto uniform = [&](double a, double b) { return a + (b - a) * unit(rng); };
    heights_.push_back(uniform(1.65, 1.85));
    KeyframePath path;
    if (sitting) {
      // At a desk: sway in place, now and then a small step and back.
      const Eigen::Vector3d home(1.3 + 1.6 * i + uniform(-0.2, 0.2), uniform(3.0, 3.25), 0.0);
      path.Add(0.0, home);
      double t = 0.0;
      while (t < duration_s + 5.0) {
        const double dwell = uniform(4.0, 9.0);
        path.Wait(dwell);
        const Eigen::Vector3d step =
            home + Eigen::Vector3d(uniform(-0.3, 0.3), uniform(-0.15, 0.1), 0.0);
        path.MoveTo(step, 0.4);
        path.Wait(uniform(1.0, 3.0));
        path.MoveTo(home, 0.4);
        t = path.end_time();
      }
    } else {
      // Across the view and back, with stops; the first person starts in view, walking.
      bool to_right = (i % 2 == 0);
      double x = i == 0 ? uniform(1.8, 2.4) : (to_right ? o.walk_x0 : o.walk_x1);
      path.Add(0.0, Eigen::Vector3d(x, uniform(o.walk_y0, o.walk_y1), 0.0));
      if (i > 0) path.Wait(2.5 * i + uniform(0.0, 2.0));
      while (path.end_time() < duration_s + 5.0) {
        const double speed = uniform(0.6, 1.1);
        const Eigen::Vector3d goal(to_right ? o.walk_x1 : o.walk_x0, uniform(o.walk_y0, o.walk_y1),
                                   0.0);
        const Eigen::Vector3d from = path.Position(path.end_time());
        if (unit(rng) < 0.6) {  // stop somewhere in view, then go on
          const double f = uniform(0.35, 0.65);
          const Eigen::Vector3d mid =
              from + f * (goal - from) + Eigen::Vector3d(0, uniform(-0.3, 0.3), 0);
          path.MoveTo(Eigen::Vector3d(mid.x(), std::clamp(mid.y(), o.walk_y0, o.walk_y1), 0.0),
                      speed);
          path.Wait(uniform(0.8, 3.0));
        }
        path.MoveTo(goal, speed);
        path.Wait(uniform(0.5, 3.0));
        to_right = !to_right;
      }
    }
    people_.push_back(path);
  }
  // The pushed box: two stop-and-go pushes, then pushed back later.
  {
    std::mt19937_64 rng(seed * 0x94D049BB133111EBULL + 7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const Eigen::Vector3d p0 = o.pushed_box_start;
    pushed_.Add(0.0, p0, 0.0);
    pushed_.Add(0.15 * duration_s, p0, 0.0);
    pushed_.MoveTo(p0 + Eigen::Vector3d(0.6, -0.15, 0), 0.45, 0.12);
    pushed_.Wait(1.0 + unit(rng));
    pushed_.MoveTo(p0 + Eigen::Vector3d(1.2 + 0.3 * unit(rng), -0.3, 0), 0.5, 0.25);
    pushed_.Add(std::max(pushed_.end_time(), 0.6 * duration_s), pushed_.Position(1e9), 0.25);
    pushed_.MoveTo(p0 + Eigen::Vector3d(0.4, 0.15, 0), 0.4, -0.1);
  }
  // The desk item: static for ~45 % of the sequence, then lifted and put down further right.
  {
    const Eigen::Vector3d p0 = o.desk_item_start;
    const double t0 = 0.45 * duration_s;
    item_.Add(0.0, p0, 0.0);
    item_.Add(t0, p0, 0.0);
    item_.Add(t0 + 0.6, p0 + Eigen::Vector3d(0.03, -0.05, 0.15), 0.2);
    item_.Add(t0 + 1.6, p0 + Eigen::Vector3d(0.3, -0.12, 0.15), 0.5);
    item_.Add(t0 + 2.2, p0 + Eigen::Vector3d(0.35, -0.15, 0.0), 0.6);
  }
}

void Movers::AppendQuads(double t, const std::function<Eigen::Vector3d(double)>& camera_position_at,
                         std::vector<DrawQuad>* quads) const {
  for (size_t i = 0; i < people_.size(); ++i) {
    const KeyframePath& path = people_[i];
    const PersonLook& look = looks_[i];
    const Texture* first = look.gait.front();
    const Eigen::Vector3d p = path.Position(t);
    const double dist = path.Distance(t);
    const double bob = 0.025 * std::abs(std::sin(kPi * dist / 0.75));
    const double height = heights_[i];
    const double width = height * first->width() / first->height();
    // Billboard through the body centre, facing the camera; at rest, facing where the camera was
    // when the rest began; walking off, turning from there back to the camera.
    auto bearing_to_camera = [&](double when) {
      const Eigen::Vector2d d = (camera_position_at(std::max(0.0, when)) - p).head<2>();
      return d.norm() < 1e-3 ? kPi / 2 : std::atan2(d.y(), d.x());
    };
    const double rest_since = path.RestSince(t);
    double bearing = bearing_to_camera(std::isnan(rest_since) ? t : rest_since);
    if (std::isnan(rest_since)) {
      const double rest_end = path.LastRestEnd(t);
      if (!std::isnan(rest_end) && t - rest_end < kTurnBackS) {
        const double from = bearing_to_camera(path.RestSince(rest_end - 1e-9));
        const double turn = std::remainder(bearing - from, 2.0 * kPi);
        bearing = from + Smooth((t - rest_end) / kTurnBackS) * turn;
      }
    }
    const Eigen::Vector2d to_cam(std::cos(bearing), std::sin(bearing));
    const Eigen::Vector3d right(-to_cam.y(), to_cam.x(), 0.0);  // as seen from the camera
    const bool mirror = path.Heading(t).dot(right.head<2>()) < 0.0;
    const size_t phase =
        look.gait.size() > 1
            ? static_cast<size_t>(std::floor(dist / 1.4 * look.gait.size())) % look.gait.size()
            : 0;
    DrawQuad q;
    q.texture = look.gait[phase];
    q.origin = p - 0.5 * width * right + Eigen::Vector3d(0, 0, height + bob);
    q.axis_u = width * right;
    q.axis_v = Eigen::Vector3d(0, 0, -height);
    const double w = q.texture->width(), h = q.texture->height();
    q.tex_rect = mirror ? cv::Rect2d(w - 0.5, -0.5, -w, h) : cv::Rect2d(-0.5, -0.5, w, h);
    q.object_id = static_cast<int>(i) + 1;
    quads->push_back(q);
  }
  AppendRigid(office_->pushed_box, Pose(pushed_.Position(t, true), pushed_.Yaw(t, true)),
              kPushedBoxId, quads);
  AppendRigid(office_->desk_item, Pose(item_.Position(t, true), item_.Yaw(t, true)), kDeskItemId,
              quads);
}

std::vector<ObjectState> Movers::States(double t) const {
  constexpr double kDt = 1.0 / 60.0;
  std::vector<ObjectState> states;
  for (size_t i = 0; i < people_.size(); ++i) {
    const Eigen::Vector2d h = people_[i].Heading(t);
    const bool moving = (people_[i].Position(t + kDt) - people_[i].Position(t - kDt)).norm() > 1e-4;
    states.push_back(
        {static_cast<int>(i) + 1, Pose(people_[i].Position(t), std::atan2(h.y(), h.x())), moving});
  }
  auto rigid = [&](const KeyframePath& path, int id) {
    const bool moving =
        (path.Position(t + kDt, true) - path.Position(t - kDt, true)).norm() > 1e-4 ||
        std::abs(path.Yaw(t + kDt, true) - path.Yaw(t - kDt, true)) > 1e-4;
    states.push_back({id, Pose(path.Position(t, true), path.Yaw(t, true)), moving});
  };
  rigid(pushed_, kPushedBoxId);
  rigid(item_, kDeskItemId);
  return states;
}

}  // namespace dynorb::synth

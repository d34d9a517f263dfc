// Moving objects of a synthetic sequence and their paths: 1-3 people walking across the view in
// front of the camera (stopping and starting again), or standing at the desks and moving little
// (sitting presets); a box pushed over the floor in stop-and-go moves; an item on a desk that
// stays put for a while, then is picked up and put down elsewhere.
//
// People are vertical billboards facing the camera, textured with RGBA cut-outs of real people
// (or procedural articulated figures), mirrored by walking direction, bobbing while they walk;
// the renderer gives them a body-shaped depth bulge. A person who stands still keeps the
// orientation they had when they stopped (a card that kept turning towards a moving camera would
// be a slowly rotating, i.e. moving, object while objects.txt calls it still); on walking off they
// turn back towards the camera within kTurnBackS. Object ids (mask values): people 1..3,
// pushed box 4, desk item 5. Everything is a deterministic function of time. Immutable after
// construction; thread-safe.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "dynorb/core/rigid3.h"
#include "dynorb/synth/office.h"
#include "dynorb/synth/renderer.h"

namespace dynorb::synth {

constexpr int kPushedBoxId = 4;
constexpr int kDeskItemId = 5;
constexpr double kTurnBackS = 0.5;  // A person walking off turns back to the camera within this.

// Piecewise-linear motion through timed keyframes (position + yaw about z); before the first
// and after the last keyframe the object rests. `eased` uses smoothstep between keys (pushes).
class KeyframePath {
 public:
  void Add(double t_s, const Eigen::Vector3d& position, double yaw_rad = 0.0);
  void Wait(double duration_s);  // stays at the last key
  void MoveTo(const Eigen::Vector3d& position, double speed_mps, double yaw_rad = 0.0);
  double end_time() const { return keys_.empty() ? 0.0 : keys_.back().t; }
  Eigen::Vector3d Position(double t_s, bool eased = false) const;
  double Yaw(double t_s, bool eased = false) const;
  // Distance travelled up to t (drives the gait) and the last non-zero horizontal direction.
  double Distance(double t_s) const;
  Eigen::Vector2d Heading(double t_s) const;
  // At rest at t (before the first key, after the last, or between two keys at the same place):
  // the time the rest began (clamped to >= first key time). Moving: NaN.
  double RestSince(double t_s) const;
  // Moving at t: the end time of the latest rest before t (NaN when it never rested before).
  double LastRestEnd(double t_s) const;

 private:
  struct Key {
    double t;
    Eigen::Vector3d p;
    double yaw;
    double dist;  // cumulative path length at this key
  };
  size_t Segment(double t) const;  // index i with keys_[i].t <= t < keys_[i+1].t
  std::vector<Key> keys_;
};

struct PersonLook {
  std::vector<const Texture*> gait;  // one sprite (cut-out) or a walking cycle (procedural)
  std::string source;                // file name or "procedural"
};

struct ObjectState {
  int id;
  Rigid3d world_from_object;
  bool moving;
};

class Movers {
 public:
  // `looks` must hold at least `num_people` entries.
  Movers(const Office& office, bool sitting, int num_people, double duration_s, uint64_t seed,
         std::vector<PersonLook> looks);

  // Appends all moving objects at time t. `camera_position_at(t)`: the camera centre at any time
  // (billboards face it; a resting person faces where it was when they stopped).
  void AppendQuads(double t_s, const std::function<Eigen::Vector3d(double)>& camera_position_at,
                   std::vector<DrawQuad>* quads) const;
  std::vector<ObjectState> States(double t_s) const;
  const std::vector<double>& person_heights() const { return heights_; }
  const std::vector<PersonLook>& looks() const { return looks_; }

 private:
  const Office* office_;
  std::vector<PersonLook> looks_;
  std::vector<KeyframePath> people_;
  std::vector<double> heights_, widths_;
  KeyframePath pushed_, item_;
};

}  // namespace dynorb::synth

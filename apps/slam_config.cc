#include "slam_config.h"

namespace dynorb {

void BindSlamSections(TrackerOptions* t, LocalMapperOptions* m, SystemOptions* sys,
                      std::string* vocabulary_path, ConfigSchema* schema) {
  schema->Section("place_recognition", "Place recognition (docs/place_recognition.md)")
      .Add("enabled", &sys->place_recognition,
           "keyframes get a bag of words; relocalisation tries the keyframes of the recognised "
           "place first")
      .Add("vocabulary", vocabulary_path,
           "vocabulary file written by `dynorb vocab` (empty: the built-in one)");
  LoopClosingOptions* l = &sys->loop_closing;
  schema->Section("loop_closing", "Loop closing (docs/loop_closing.md)")
      .Add("enabled", &l->enabled,
           "detect revisited places and correct the drift (needs place_recognition)")
      .Add("min_keyframes", &l->min_keyframes, "no loop in a map with fewer keyframes")
      .Add("min_keyframes_between", &l->min_keyframes_between,
           "keyframes after a closed loop before the next")
      .Add("consistency", &l->consistency, "consecutive keyframes whose loop candidates must agree")
      .Add("strong_covisibility", &l->strong_covisibility,
           "covisibility edges with at least this many shared landmarks join the pose graph")
      .Add("pose_graph_iterations", &l->pose_graph_iterations,
           "Levenberg-Marquardt iterations of the pose graph")
      .Add("min_agreement", &l->min_agreement,
           "fraction of the loop side's landmarks in view the verified pose must find (a mover "
           "seen again closes no loop)")
      .Add("global_ba", &l->global_ba, "bundle-adjust the whole map after each loop correction")
      .Add("global_ba_thread", &l->global_ba_thread,
           "parallel run mode: the global BA on its own thread (local mapping goes on meanwhile) "
           "instead of on the mapper's")
      .Add("global_ba_iterations", &l->global_ba_iterations,
           "Levenberg-Marquardt iterations of the global bundle adjustment after its robust "
           "stage removed the outliers")
      .OnLoaded([l] { l->Validate(); });
  schema->Section("tracking", "Tracker (docs/slam_core.md)")
      .Add("refill_filtered", &sys->refill_filtered,
           "after the dynamic filter removed keypoints, detect again outside the removed area")
      .Add("refill_disk_px", &sys->refill_disk_px,
           "radius excluded around each removed keypoint (px)")
      .Add("motion_radius_px", &t->motion_radius_px,
           "search radius of motion-model tracking (level 0)")
      .Add("local_map_radius_factor", &t->local_map_radius_factor,
           "radius factor of local-map search")
      .Add("min_local_map_inliers", &t->min_local_map_inliers, "inliers needed to accept a pose")
      .Add("max_local_keyframes", &t->max_local_keyframes, "local map size (keyframes)")
      .Add("min_frames_between_keyframes", &t->min_frames_between_keyframes,
           "frames before an idle mapper may take a new keyframe")
      .Add("max_frames_between_keyframes", &t->max_frames_between_keyframes,
           "frames after which one is due")
      .Add("reference_ratio", &t->reference_ratio, "new keyframe when tracking < ratio x reference")
      .Add("close_tracked_max", &t->close_tracked_max,
           "'need close points': tracked close points below this ...")
      .Add("close_untracked_min", &t->close_untracked_min,
           "... and untracked close points above this")
      .Add("close_keyframe_min_frames", &t->close_keyframe_min_frames,
           "frames after a keyframe before 'need close points' may ask again")
      .Add("filtered_keyframe_fraction", &t->filtered_keyframe_fraction,
           "once max_frames_between_keyframes have passed, a frame whose filter removed at least "
           "this fraction of "
           "the keypoints needs close points whatever their tracked count (0: off)")
      .Add("filtered_keyframe_min_motion_m", &t->filtered_keyframe_min_motion_m,
           "... once the camera is at least this far from its reference keyframe (m) ...")
      .Add("filtered_keyframe_min_rotation_deg", &t->filtered_keyframe_min_rotation_deg,
           "... or turned at least this much from it (deg; both 0: no motion condition)")
      .Add("new_close_points", &t->new_close_points,
           "landmarks created from depth per new keyframe: all closer than ThDepth, at least this "
           "many nearest")
      .Add("relocalization_candidates", &t->relocalization_candidates,
           "keyframes tried when lost, in all")
      .Add("relocalization_place_candidates", &t->relocalization_place_candidates,
           "... of which at most this many found by place recognition first, then the most recent "
           "ones")
      .Add("provisional_min_found", &t->provisional_min_found,
           "landmarks of one keyframe found in fewer frames must agree with the established map's "
           "pose (0: off)")
      .Add("provisional_min_established", &t->pose.min_established,
           "established observations needed before provisional ones are held back")
      .Add("provisional_gate_factor", &t->pose.provisional_gate_factor,
           "chi2 gate factor (0..1] for provisional landmarks joining the established pose")
      .Add("pose_min_gate_scale", &t->pose.min_gate_scale,
           "the pose solve's chi2 gates follow the measured keypoint noise down to this scale "
           "(0..1]; 1: fixed 1-px gates")
      .Add("pose_depth_fallback", &t->pose.depth_fallback,
           "an RGB-D match whose depth fails the pose solve's gate but whose pixel fits joins "
           "without its depth (false: dropped, as ORB-SLAM2)")
      .Add("motion_prior_sigma_m", &t->motion_prior_sigma_m,
           "prior on the camera centre from a smoothed constant-velocity model, standard deviation "
           "(m; 0: off)")
      .Add("motion_prior_velocity_gain", &t->motion_prior_velocity_gain,
           "gain (0..1] of the exponential average of the camera centre's velocity")
      .Add("dynamic_votes_to_erase", &t->dynamic_votes_to_erase,
           "a landmark observed moving this many times (projecting next to a keypoint the filter "
           "saw move, at that keypoint's depth) with no static inlier match in between is erased "
           "(0: never)")
      .Add("dynamic_vote_radius_px", &t->dynamic_votes.radius_px,
           "... next to: within this many pixels of the landmark's projection")
      .Add("dynamic_vote_band_m", &t->dynamic_votes.band_m,
           "... at its depth: within band_m + band_rel * z^2 of the landmark's depth (m)")
      .Add("dynamic_vote_band_rel", &t->dynamic_votes.band_rel, "... (1/m)")
      .OnLoaded([t] { t->Validate(); });
  schema->Section("mapping", "Local mapper (docs/slam_core.md)")
      .Add("local_bundle_adjustment", &m->local_bundle_adjustment, "run local BA")
      .Add("local_ba_keyframes", &m->local_ba_keyframes, "free keyframes in local BA")
      .Add("local_ba_fixed_keyframes", &m->local_ba_fixed_keyframes, "fixed keyframes in local BA")
      .Add("ba_first_iterations", &m->bundle_adjustment.first_iterations, "robust LM iterations")
      .Add("ba_second_iterations", &m->bundle_adjustment.second_iterations,
           "LM iterations without outliers")
      .Add("keyframe_culling", &m->keyframe_culling, "cull redundant keyframes")
      .Add("redundant_ratio", &m->redundant_ratio,
           "a keyframe is redundant when this fraction of its close landmarks ...")
      .Add("redundant_observers", &m->redundant_observers,
           "... is seen by at least this many other keyframes")
      .Add("min_found_ratio", &m->min_found_ratio,
           "recent landmarks found in fewer than this fraction of the frames that predicted them "
           "are culled")
      .Add("triangulation_neighbours", &m->triangulation_neighbours,
           "covisibles searched for new points")
      .Add("free_space_ratio", &m->free_space_ratio,
           "reject triangulations nearer than this fraction of the depth measured around a "
           "depthless keypoint (0: off)")
      .OnLoaded([m] { m->Validate(); });
}

SystemOptions MakeSystemOptions(const SystemConfig& config, const RunRequest& cli,
                                const TrackerOptions& tracker, const LocalMapperOptions& mapper,
                                const SystemOptions& bound) {
  SystemOptions options = bound;
  options.tracker = tracker;
  options.mapper = mapper;
  options.sensor.camera = config.camera.camera;
  options.sensor.bf = config.camera.bf;
  options.sensor.th_depth_m = config.camera.close_depth_threshold_m();
  options.sensor.disparity_sigma_px = config.camera.disparity_sigma_px;
  options.orb.n_features = config.orb.n_features;
  options.orb.scale_factor = config.orb.scale_factor;
  options.orb.n_levels = config.orb.n_levels;
  options.orb.ini_th_fast = config.orb.ini_th_fast;
  options.orb.min_th_fast = config.orb.min_th_fast;
  options.tracker.seed = cli.seed;
  options.run_mode = cli.run_mode == "parallel" ? RunMode::kParallel : RunMode::kSequential;
  options.front_end_threads = cli.front_end_threads;
  return options;
}

}  // namespace dynorb

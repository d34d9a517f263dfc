#include "run_pipeline.h"

#include <cstdio>
#include <deque>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "builtin_config.h"
#include "dynamic_labels.h"
#include "dynorb/core/error.h"
#include "dynorb/core/prefetcher.h"
#include "dynorb/core/stats.h"
#include "dynorb/core/timer.h"
#include "dynorb/eval/evaluate.h"
#include "dynorb/eval/report.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/io/config.h"
#include "dynorb/io/frame_range.h"
#include "dynorb/io/point_cloud_io.h"
#include "dynorb/io/trajectory_io.h"
#include "dynorb/io/tum_sequence.h"
#include "dynorb/map/landmark_summary.h"
#include "dynorb/place_recognition/vocabulary.h"
#include "dynorb/system/system.h"
#include "map_export.h"
#include "preload_budget.h"
#include "progress_bar.h"
#include "run_checks.h"
#include "run_modes.h"
#include "run_report.h"
#include "slam_config.h"

namespace dynorb {
namespace {

namespace fs = std::filesystem;

// The configuration of a run: the system keys, the SLAM sections (`tracking:` refill_*,
// `place_recognition:`, ...) and the mode's own section, bound to one schema.
struct RunSchema {
  explicit RunSchema(const std::string& mode_name) {
    BindSystemConfig(&config, &schema);
    BindSlamSections(&tracker_options, &mapper_options, &system_options, &vocabulary_path, &schema);
    mode = MakeRunModeFactory(mode_name);
    if (mode) mode->BindConfig(&schema);
  }
  RunSchema(const RunSchema&) = delete;
  RunSchema& operator=(const RunSchema&) = delete;

  SystemConfig config;
  ConfigSchema schema;
  TrackerOptions tracker_options;
  LocalMapperOptions mapper_options;
  SystemOptions system_options;
  std::string vocabulary_path;
  std::unique_ptr<RunModeFactory> mode;
};

}  // namespace

void CheckRunConfigFiles(const std::string& mode, const std::vector<std::string>& files) {
  RunSchema bound(mode);
  // Over a complete camera config (the TUM fr3 calibration): an overlay may hold a few keys only.
  bound.schema.LoadString(builtin_config_internal::kTumFreiburg3Yaml,
                          "built-in config/tum_fr3.yaml");
  bound.schema.LoadFiles(files);
}

nlohmann::json RunPipeline(const RunRequest& cli) {
  std::error_code dataset_error;
  if (!fs::is_directory(cli.dataset, dataset_error)) {
    // Only a reason other than absence is worth naming (e.g. permission denied).
    const bool other = dataset_error && dataset_error != std::errc::no_such_file_or_directory;
    throw InputError("dataset folder not found" +
                     (other ? " (" + dataset_error.message() + ")" : std::string()) + ": " +
                     cli.dataset);
  }
  if (cli.overlay_every < 1) throw InputError("overlay_every must be >= 1");
  if (cli.pipeline_depth < 1 || cli.pipeline_depth > kMaxPipelineDepth) {
    throw InputError("pipeline depth must be 1.." + std::to_string(kMaxPipelineDepth) + ", got " +
                     std::to_string(cli.pipeline_depth));
  }
  std::string config_path = cli.config;
  // A TUM sequence folder without camera.yaml: its camera's built-in calibration.
  std::optional<BuiltInConfig> builtin_config;
  if (config_path.empty()) {
    config_path = (fs::path(cli.dataset) / "camera.yaml").string();
    if (!fs::exists(config_path)) {
      builtin_config = BuiltInConfigForDataset(cli.dataset);
      if (!builtin_config) {
        throw InputError(
            "no --config given and the dataset has no camera.yaml (use e.g. --config "
            "config/tum_fr3.yaml; a folder named like a TUM sequence, "
            "rgbd_dataset_freiburg1/2/3_*, gets that camera's calibration)");
      }
      config_path = "built-in " + builtin_config->file;
      std::cerr << "dynorb run: " << cli.dataset << " has no camera.yaml: using the "
                << builtin_config->camera << " calibration (" << builtin_config->file
                << ", chosen by the folder's name); pass --config to use another\n";
    }
  }
  // One schema: the system keys plus the chosen mode's own section. (Declared before the System:
  // the mode's factory outlives the filter it made.)
  RunSchema bound(cli.mode);
  SystemConfig& config = bound.config;
  ConfigSchema& schema = bound.schema;
  TrackerOptions& tracker_options = bound.tracker_options;
  LocalMapperOptions& mapper_options = bound.mapper_options;
  SystemOptions& system_options = bound.system_options;
  const std::string& vocabulary_path = bound.vocabulary_path;
  const std::unique_ptr<RunModeFactory>& mode = bound.mode;
  if (builtin_config) {
    schema.LoadString(builtin_config->yaml, config_path);
  } else {
    schema.Load(config_path);
  }
  if (!cli.config_overlays.empty()) {
    schema.LoadFiles(cli.config_overlays);  // Their keys override; everything is validated again.
    for (const std::string& overlay : cli.config_overlays) config_path += " + " + overlay;
  }
  TumSequence sequence(cli.dataset, config.dataset);
  const auto [first, last] = SelectFrames(cli.frames, sequence.size());
  OutputFolder out_folder(cli.out);  // Removed again if still empty when the run fails.
  {
    std::vector<std::string> targets;
    for (const char* name : {"trajectory.txt", "keyframes.txt", "effective_config.yaml",
                             "frames.csv", "map.ply", "stats.json"})
      targets.push_back((fs::path(cli.out) / name).string());
    CheckOutputTargets(targets);  // before the run: a failure at the end would leave some written
  }

  std::optional<OutputFolder> overlay_folder;
  if (!cli.overlays.empty()) overlay_folder.emplace(cli.overlays, "overlay folder");
  if (!schema.IsSet("tracking.max_frames_between_keyframes")) {  // ORB-SLAM2: one second of frames.
    tracker_options.max_frames_between_keyframes = std::max(1, static_cast<int>(config.camera.fps));
  }
  if (system_options.place_recognition && !vocabulary_path.empty()) {
    system_options.vocabulary =
        std::make_shared<const Vocabulary>(Vocabulary::Load(vocabulary_path));
  }
  const SystemOptions options = MakeSystemOptions(config, cli, tracker_options, mapper_options, system_options);
  std::unique_ptr<KeypointFilter> filter;
  if (mode) {
    RunModeContext context;
    context.config = &config;
    context.sensor = options.sensor;
    context.orb = options.orb;
    context.dataset = cli.dataset;
    context.models_dir = cli.models;
    context.seed = cli.seed;
    filter = mode->Create(context);
  }
  const std::optional<MaskGroundTruth> masks = MaskGroundTruth::Open(
      cli.dataset, cv::Size(options.sensor.camera.width, options.sensor.camera.height));
  const double level_scale = options.orb.scale_factor;  // Keypoint octave -> image scale ("support" truth).
  KeypointLabelStats label_stats(level_scale);
  KeypointLabelStats moving_now_stats(level_scale);  // Objects standing still at the frame ignored (objects.txt).
  std::map<std::string, KeypointLabelStats> cue_stats;  // Per filter cue (KeypointFilter::CueFlags), moving now.
  // Pose inliers and created landmarks on objects moving at the frame (empty without masks;
  // frames.csv then says -1).
  std::vector<int> inliers_on_movers, new_landmarks_on_movers;
  std::vector<double> on_movers_pixel, on_movers_support;
  long long inliers_counted = 0, landmarks_created = 0, landmarks_on_movers = 0, landmarks_on_movers_support = 0;
  System system(options, std::move(filter));
  system.set_record_keypoints(masks.has_value() || !cli.overlays.empty());
  ProgressBar progress("frames", static_cast<int>(last - first));
  Stopwatch wall;
  // PNG decoding (≈ 6 ms/frame) overlaps processing on the second core; results are unchanged.
  struct LoadedFrame {
    RgbdFrame frame;
    cv::Mat mask;   // Ground-truth moving-object mask (empty without masks).
    cv::Mat still;  // Its objects that stand still at this frame (empty: none or no objects.txt).
  };
  // A frame of the wrong size is refused as soon as it is decoded (with --preload: before the
  // remaining frames are decoded).
  const int width = options.sensor.camera.width, height = options.sensor.camera.height;
  auto load = [&sequence, &masks, &config_path, first, width, height](size_t k) {
    LoadedFrame loaded;
    loaded.frame = sequence.Frame(first + k);
    const cv::Mat& rgb = loaded.frame.rgb;
    if (rgb.cols != width || rgb.rows != height) {
      throw InputError(sequence.ResolvePath(sequence.entries()[first + k].rgb_path) + ": image is " +
                       std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows) + " but " + config_path + " says " +
                       std::to_string(width) + "x" + std::to_string(height));
    }
    if (masks) {
      loaded.mask = masks->MaskAt(loaded.frame.timestamp_s);
      loaded.still = masks->StillObjectsAt(loaded.mask, loaded.frame.timestamp_s);
    }
    return loaded;
  };
  // --preload: every frame decoded before the clock starts; otherwise decoded on a prefetch thread.
  std::vector<LoadedFrame> preloaded;
  std::unique_ptr<Prefetcher<LoadedFrame>> prefetcher;
  double preload_seconds = 0.0;
  if (cli.preload) {
    const PinholeCamera& camera = options.sensor.camera;
    CheckPreloadFits(last - first, PreloadBytes(last - first, camera.width, camera.height, masks.has_value()),
                     PhysicalMemoryBytes());
    preloaded.reserve(last - first);
    for (size_t k = 0; k < last - first; ++k) preloaded.push_back(load(k));
    preload_seconds = wall.ElapsedMs() / 1000.0;
    wall.Restart();
  } else {
    prefetcher = std::make_unique<Prefetcher<LoadedFrame>>(last - first, load);
  }
  const double cpu_start = ProcessCpuSeconds();
  double overlay_write_wall_s = 0.0, overlay_write_cpu_s = 0.0;  // --save-overlays' image files
  auto next_loaded = [&](size_t i) {
    return cli.preload ? std::move(preloaded[i - first]) : prefetcher->Next();
  };
  // The filter draws its overlay only on the frames that are saved (the drawing is timed).
  auto wants_overlay = [&](size_t i) {
    return !cli.overlays.empty() && (i - first) % static_cast<size_t>(cli.overlay_every) == 0;
  };
  // Pipelining: the front ends of the next `depth` frames run ahead of this frame's tracking.
  const size_t depth = cli.pipeline ? static_cast<size_t>(cli.pipeline_depth) : 0;
  std::deque<LoadedFrame> upcoming;
  // The ground-truth statistics of one frame (its record, its masks).
  auto account = [&](const FrameRecord& record, const cv::Mat& mask, const cv::Mat& still) {
    // Every frame with a mask counts here, judged or not: a mover the pose rests on is a mover.
    // A frame without one is unknown (-1 in frames.csv), not "none on movers".
    if (mask.empty()) {
      inliers_on_movers.push_back(-1);
      new_landmarks_on_movers.push_back(-1);
      return;
    }
    const KeypointsOnObjects on = CountOnObjects(record.inliers, mask, still, level_scale);
    const KeypointsOnObjects created = CountOnObjects(record.new_landmarks, mask, still, level_scale);
    inliers_on_movers.push_back(on.pixel);
    new_landmarks_on_movers.push_back(created.pixel);
    landmarks_created += static_cast<long long>(record.new_landmarks.size());
    landmarks_on_movers += created.pixel;
    landmarks_on_movers_support += created.support;
    if (record.pose_valid) {
      on_movers_pixel.push_back(on.pixel);
      on_movers_support.push_back(on.support);
      inliers_counted += static_cast<long long>(record.inliers.size());
    }
    if (record.judged) {  // An unjudged frame's keypoints were withheld, not labelled.
      // One truth per frame and mask for every statistic (still objects ignored for "moving now").
      const KeypointTruth now = ComputeKeypointTruth(record.detected, mask, still, level_scale);
      const KeypointTruth all =
          still.empty() ? now : ComputeKeypointTruth(record.detected, mask, cv::Mat(), level_scale);
      label_stats.Add(all, record.keep);
      moving_now_stats.Add(now, record.keep);
      for (const auto& [cue, moving] : record.cue_flags) {
        std::vector<bool> keep(moving.size());
        for (size_t k = 0; k < moving.size(); ++k) keep[k] = !moving[k];
        cue_stats.try_emplace(cue, level_scale).first->second.Add(now, keep);
      }
    }
  };
  // With --preload the masks are in memory already: the statistics are computed after the run,
  // so the timed loop does only what a live run does. Otherwise each frame's masks are dropped
  // after it, so its statistics are computed in the loop.
  struct FrameMasks {
    cv::Mat mask, still;
  };
  std::vector<FrameMasks> deferred;
  DepthScaleCheck depth_check;  // The first frames' depth scale (run_checks.h).
  for (size_t i = first; i < last; ++i) {
    // Frames i .. i + depth loaded (upcoming starts at frame i).
    while (upcoming.size() < depth + 1 && i + upcoming.size() < last) {
      upcoming.push_back(next_loaded(i + upcoming.size()));
    }
    const LoadedFrame loaded = std::move(upcoming.front());
    upcoming.pop_front();
    const RgbdFrame& frame = loaded.frame;
    const bool save_overlay = wants_overlay(i);
    system.set_record_overlays(save_overlay);
    std::vector<System::NextFrame> ahead;
    for (size_t j = 0; j < upcoming.size(); ++j) {
      ahead.push_back({upcoming[j].frame.timestamp_s, upcoming[j].frame.rgb, upcoming[j].frame.depth_m,
                       wants_overlay(i + 1 + j)});
    }
    depth_check.Add(frame.depth_m);
    const FrameRecord& record = system.ProcessFrame(frame.timestamp_s, frame.rgb, frame.depth_m, ahead);
    if (masks) {
      if (cli.preload) {
        deferred.push_back({loaded.mask, loaded.still});
      } else {
        account(record, loaded.mask, loaded.still);
      }
    }
    if (save_overlay) {
      // Drawing and encoding the image is not part of the run's CPU time: this thread's CPU
      // time for it is taken off (the filter's own drawing stays in its stage time).
      const Stopwatch write_watch;
      const double write_cpu_start = ThreadCpuSeconds();
      const cv::Mat base = record.filter_overlay.empty() ? frame.rgb : record.filter_overlay;
      char name[32];
      std::snprintf(name, sizeof(name), "%06zu.png", i);
      const std::string overlay_path = (fs::path(cli.overlays) / name).string();
      if (!cv::imwrite(overlay_path, DrawKeypointOverlay(base, record.detected, record.keep)))
        throw InputError("cannot write overlay " + overlay_path);
      overlay_write_wall_s += write_watch.ElapsedMs() / 1000.0;
      overlay_write_cpu_s += ThreadCpuSeconds() - write_cpu_start;
    }
    if (!cli.quiet) {
      const int done = static_cast<int>(i - first + 1);
      char hz[64];
      std::snprintf(hz, sizeof(hz), "%.1f Hz, %s", done / std::max(1e-9, wall.ElapsedMs() / 1000.0),
                    ToString(system.records().back().state));
      progress.Update(done, hz);
    }
  }
  system.Finish();

  const Trajectory trajectory = system.FrameTrajectory();
  RunSummaryInputs inputs;
  inputs.dataset = cli.dataset;
  inputs.config = config_path;
  inputs.mode = cli.mode;
  inputs.run_mode = cli.run_mode;
  inputs.pipeline = cli.pipeline;
  inputs.pipeline_depth = cli.pipeline ? cli.pipeline_depth : 0;
  inputs.front_end_threads = cli.pipeline ? system.front_end_threads() : 0;
  inputs.seed = cli.seed;
  inputs.first_frame = first;
  // Wall time keeps the writing: the other threads go on meanwhile, so taking it off would
  // count their work as free (session-55 review: half the real time with the pipeline).
  inputs.wall_seconds = wall.ElapsedMs() / 1000.0;
  inputs.cpu_seconds = ProcessCpuSeconds() - cpu_start - overlay_write_cpu_s;
  inputs.overlay_write_seconds = overlay_write_wall_s;
  for (size_t k = 0; k < deferred.size(); ++k) account(system.records()[k], deferred[k].mask, deferred[k].still);
  inputs.preload = cli.preload;
  inputs.preload_seconds = preload_seconds;
  // Ground truth that does not fit the run (another clock, another sequence) costs the ATE, not
  // the run's outputs: the evaluator's complaint becomes a warning.
  std::optional<EvalResult> ate;
  std::vector<std::string> eval_warnings;
  if (sequence.HasGroundTruth() && trajectory.size() >= 3) {
    try {
      ate = EvaluateAgainstGroundTruth(sequence.ground_truth(), trajectory, system.records());
      for (const std::string& w : ate->warnings) eval_warnings.push_back("evaluation: " + w);
    } catch (const InputError& e) {
      eval_warnings.push_back(std::string("no ATE/RPE: ") + e.what());
    }
  }
  nlohmann::json stats = BuildRunStats(system, inputs, ate);
  RunCheckLimits limits;
  limits.depth_map_factor = config.camera.depth_map_factor;
  limits.min_init_points = tracker_options.min_init_points;
  limits.min_init_depth_points = tracker_options.min_init_depth_points;
  limits.first_frame = first;
  std::vector<std::string> warnings = RunWarnings(depth_check, system.records(), limits);
  warnings.insert(warnings.end(), eval_warnings.begin(), eval_warnings.end());
  stats["warnings"] = warnings;
  if (masks) {
    stats["dynamic_keypoints"] = label_stats.ToJson();
    if (masks->has_object_states()) {
      nlohmann::json now = moving_now_stats.ToJson();
      now["definition"] =
          "as above, but keypoints on an object that stands still at that frame (objects.txt moving = 0: a person "
          "who stopped, the desk item before it starts) are not counted";
      stats["dynamic_keypoints"]["moving_now"] = now;
    }
    double pixel_total = 0.0, support_total = 0.0;
    int frames_with_any = 0;
    for (size_t k = 0; k < on_movers_pixel.size(); ++k) {
      pixel_total += on_movers_pixel[k];
      support_total += on_movers_support[k];
      frames_with_any += on_movers_pixel[k] > 0 ? 1 : 0;
    }
    const double inliers_total = std::max<double>(1.0, static_cast<double>(inliers_counted));
    stats["inliers_on_moving_objects"] = {
        {"per_frame", StatsJson(on_movers_pixel)},
        {"support_per_frame", StatsJson(on_movers_support)},
        {"fraction_of_inliers", pixel_total / inliers_total},
        {"support_fraction_of_inliers", support_total / inliers_total},
        {"frames_with_any", frames_with_any},
        {"definition",
         "pose inliers of each tracked frame (keypoints matched to a landmark after the final pose optimisation) "
         "whose centre pixel is on an object moving at that frame (support: or whose FAST circle touches one)"}};
    stats["landmarks_created_on_moving_objects"] = {
        {"created", landmarks_created},
        {"on_moving_objects", landmarks_on_movers},
        {"support_on_moving_objects", landmarks_on_movers_support},
        {"definition",
         "landmarks the tracker created from a keyframe's depth whose keypoint lies on an object moving at that "
         "frame (support: or touches one with its FAST circle)"}};
    std::vector<ErasedLandmark> erased_landmarks;
    for (const FrameRecord& r : system.records())
      erased_landmarks.insert(erased_landmarks.end(), r.erased_landmarks.begin(),
                              r.erased_landmarks.end());
    const OriginTruth erased = ClassifyErasedLandmarks(erased_landmarks, *masks);
    stats["landmarks_erased_as_dynamic"]["made_on_dynamic_objects"] = erased.made_on_objects;
    stats["landmarks_erased_as_dynamic"]["origin_known"] = erased.with_origin;
    stats["landmarks_erased_as_dynamic"]["made_on_definition"] =
        "of the erased landmarks whose oldest observing keyframe was still in the map "
        "(origin_known), "
        "those whose keypoint there lay on a dynamic object of the ground-truth masks (moving at "
        "that frame or not)";
    if (!cue_stats.empty()) {
      stats["dynamic_keypoints"]["by_cue_definition"] =
          "per cue of the filter: the keypoints it flagged as moving, judged against the "
          "moving-now "
          "truth of moving_now (objects standing still at the frame ignored)";
    }
    for (const auto& [cue, cue_labels] : cue_stats) {
      const nlohmann::json all = cue_labels.ToJson();
      stats["dynamic_keypoints"]["by_cue"][cue] = {{"flagged", all["true_positive"].get<long long>() +
                                                                   all["false_positive"].get<long long>()},
                                                  {"precision", all["precision"]},
                                                  {"recall", all["recall"]}};
    }
  }

  // The final map: its landmarks checked against the masks; with --save-map, map.ply (its colours
  // read before any output is written).
  const std::vector<LandmarkSummary> map_landmarks =
      system.map().Read([](const MapData& map) { return SummarizeLandmarks(map); });
  std::vector<LandmarkOrigin> origins;
  origins.reserve(map_landmarks.size());
  for (const LandmarkSummary& l : map_landmarks) origins.push_back(l.origin);
  std::vector<uint8_t> dynamic_object_id;
  if (masks) {
    OriginTruth truth = ClassifyOrigins(origins, *masks);
    stats["map_landmarks_on_dynamic_objects"] = MapTruthJson(truth, map_landmarks.size());
    dynamic_object_id = std::move(truth.object_id);
  }
  std::optional<PointCloud> map_cloud;
  if (cli.save_map)
    map_cloud = MapPointCloud(map_landmarks, LandmarkColours(origins, sequence), dynamic_object_id);

  WriteTumTrajectory((fs::path(cli.out) / "trajectory.txt").string(), trajectory);
  WriteTumTrajectory((fs::path(cli.out) / "keyframes.txt").string(), system.KeyframeTrajectory());
  schema.Write((fs::path(cli.out) / "effective_config.yaml").string());
  WriteFileAtomically(
      (fs::path(cli.out) / "frames.csv").string(),
      FramesCsv(system.records(), inliers_on_movers, new_landmarks_on_movers, first));
  // map.ply next to this run's outputs only: an earlier run's is removed.
  const fs::path map_path = fs::path(cli.out) / "map.ply";
  if (map_cloud) {
    WritePlyPointCloud(map_path.string(), *map_cloud);
  } else {
    std::error_code ignored;
    fs::remove(map_path, ignored);
  }
  WriteFileAtomically((fs::path(cli.out) / "stats.json").string(), stats.dump(2) + "\n");
  out_folder.Keep();
  if (overlay_folder) overlay_folder->Keep();
  return stats;
}

}  // namespace dynorb

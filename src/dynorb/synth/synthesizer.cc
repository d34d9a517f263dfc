#include "dynorb/synth/synthesizer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <mutex>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "dynorb/core/error.h"
#include "dynorb/io/trajectory_io.h"
#include "dynorb/synth/figure.h"
#include "dynorb/synth/sequence_writer.h"

namespace dynorb::synth {
namespace fs = std::filesystem;
namespace {

constexpr double kPresetStartTimestamp = 1700000000.0;

uint64_t Mix(uint64_t a, uint64_t b) {
  uint64_t z = a * 0x9E3779B97F4A7C15ULL + b + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::vector<std::pair<std::string, cv::Mat>> LoadCutouts(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.path().extension() == ".png") files.push_back(entry.path().string());
  if (ec) throw InputError("cannot read people directory " + dir + ": " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError("no RGBA *.png cut-outs in people directory " + dir);
  std::vector<std::pair<std::string, cv::Mat>> cutouts;
  for (const std::string& f : files) {
    cv::Mat img = cv::imread(f, cv::IMREAD_UNCHANGED);
    if (img.empty()) throw InputError("cannot read person cut-out " + f);
    if (img.type() != CV_8UC4) throw InputError("person cut-out is not an 8-bit RGBA PNG: " + f);
    cv::Mat alpha;
    cv::extractChannel(img, alpha, 3);
    if (cv::countNonZero(alpha > 127) == 0)  // The person would be invisible but listed as moving.
      throw InputError("person cut-out has no opaque pixel (alpha > 127): " + f);
    cutouts.emplace_back(fs::path(f).filename().string(), img);
  }
  return cutouts;
}

}  // namespace

void SynthOptions::Validate() const {
  if (!FindPreset(preset))
    throw InputError("unknown preset '" + preset + "' (known: " + PresetNames() + ")");
  if (frames < 0 || frames > kMaxFrames)
    throw InputError("--frames must be 0.." + std::to_string(kMaxFrames) + ", got " +
                     std::to_string(frames));
  if (num_people < 0 || num_people > 3)
    throw InputError("the number of people must be 1..3 (0 = default)");
  if (supersample < 1 || supersample > 4) throw InputError("supersample must be 1..4");
  if (threads < 0) throw InputError("threads must be >= 0");
  if (!people_dir.empty() && !fs::is_directory(people_dir))
    throw InputError("people directory not found: " + people_dir);
  if (texture_dir_explicit && !fs::is_directory(texture_dir))
    throw InputError("texture directory not found: " + texture_dir);
  if (!trajectory_file.empty() && !fs::is_regular_file(trajectory_file))
    throw InputError("trajectory file not found: " + trajectory_file);
}

SequenceSynth::SequenceSynth(const SynthOptions& options)
    : options_(options), camera_(TumFreiburg3Camera()), exposure_(Mix(options.seed, 5), 0.05, 0.5) {
  options_.Validate();
  preset_ = *FindPreset(options_.preset);
  sensor_.noise = options_.noise;

  // Cut-outs first: a bad people directory fails before the scene is built.
  const auto cutouts = options_.people_dir.empty() ? std::vector<std::pair<std::string, cv::Mat>>{}
                                                   : LoadCutouts(options_.people_dir);
  const bool have_textures =
      !options_.texture_dir.empty() && fs::is_directory(options_.texture_dir);
  if (!have_textures)
    warnings_.push_back("texture directory " + options_.texture_dir +
                        " not found: procedural textures only");
  PhotoLibrary photos(have_textures ? options_.texture_dir : "", options_.texture_dir_explicit);
  if (have_textures && !photos.missing().empty())
    warnings_.push_back(std::to_string(photos.missing().size()) + " photographs missing in " +
                        options_.texture_dir + ": procedural stand-ins used");
  office_ = std::make_unique<Office>();
  BuildOffice(options_.seed, photos, office_.get());

  const Rigid3d start = LookAt(office_->camera_anchor, office_->look_at);
  if (!options_.trajectory_file.empty()) {
    const Trajectory trajectory = ReadTumTrajectory(options_.trajectory_file);
    path_ = std::make_unique<CameraPath>(trajectory, start);
    const fs::path assoc = fs::path(options_.trajectory_file).parent_path() / "associations.txt";
    if (fs::is_regular_file(assoc)) {
      times_ = ReadFrameTimes(assoc.string(), path_->first_timestamp_s(), path_->duration_s());
      timestamps_source_ = assoc.string();
      if (options_.frames > 0 && options_.frames < num_frames()) times_.resize(options_.frames);
      if (options_.frames > num_frames())
        warnings_.push_back("only " + std::to_string(num_frames()) + " frames in " +
                            assoc.string());
    } else {
      const double frames_at_30hz = std::floor(path_->duration_s() * 30.0) + 1.0;
      if (options_.frames == 0 && !(frames_at_30hz <= SynthOptions::kMaxFrames)) {
        throw InputError(options_.trajectory_file + " lasts " +
                         std::to_string(path_->duration_s()) + " s: more than " +
                         std::to_string(SynthOptions::kMaxFrames) +
                         " frames at 30 Hz (pass --frames N)");
      }
      const int n = options_.frames > 0 ? options_.frames : static_cast<int>(frames_at_30hz);
      times_ = MakeFrameTimes(n, path_->first_timestamp_s(), options_.seed);
      timestamps_source_ = "30 Hz from the trajectory start";
    }
  } else {
    path_ = std::make_unique<CameraPath>(preset_, office_->camera_anchor, office_->look_at,
                                         options_.seed);
    const int n =
        options_.frames > 0 ? options_.frames : static_cast<int>(preset_.duration_s * 30.0);
    times_ = MakeFrameTimes(n, kPresetStartTimestamp, options_.seed);
    timestamps_source_ = "30 Hz";
  }

  const int people = options_.num_people > 0 ? options_.num_people : 2;
  std::vector<PersonLook> looks(people);
  if (!options_.people_dir.empty()) {
    std::vector<size_t> order(cutouts.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    cv::RNG rng(Mix(options_.seed, 11));
    for (size_t i = order.size(); i > 1; --i)
      std::swap(order[i - 1], order[rng.uniform(0, static_cast<int>(i))]);
    for (int i = 0; i < people; ++i) {
      const auto& [name, image] = cutouts[order[i % order.size()]];
      sprite_textures_.push_back(std::make_unique<Texture>(MakeSprite(image)));
      looks[i].gait = {sprite_textures_.back().get()};
      looks[i].source = name;
    }
  } else {
    for (int i = 0; i < people; ++i) {
      for (const cv::Mat& sprite : MakeFigureSprites(Mix(options_.seed, 100 + i), 8)) {
        sprite_textures_.push_back(std::make_unique<Texture>(MakeSprite(sprite)));
        looks[i].gait.push_back(sprite_textures_.back().get());
      }
      looks[i].source = "procedural";
    }
  }
  for (const PersonLook& l : looks) sprite_names_.push_back(l.source);
  const double duration = times_.back().t_s + 1.0 / 30.0;
  movers_ = std::make_unique<Movers>(*office_, preset_.sitting, people, duration, options_.seed,
                                     std::move(looks));
}

std::unique_ptr<Renderer> SequenceSynth::MakeRenderer() const {
  return std::make_unique<Renderer>(camera_, options_.supersample);
}

SynthFrame SequenceSynth::RenderFrame(int index, Renderer* renderer) const {
  SynthFrame frame;
  frame.index = index;
  frame.time = times_.at(index);
  const double t = frame.time.t_s;
  frame.world_from_cam = path_->WorldFromCam(t);
  std::vector<DrawQuad> quads = office_->scene.static_quads;
  if (!options_.static_twin) {
    movers_->AppendQuads(t, [this](double when) { return path_->WorldFromCam(when).translation; }, &quads);
    frame.objects = movers_->States(t);
  }
  RenderedFrame rendered;
  renderer->Render(quads, frame.world_from_cam.Inverse(), &rendered);
  frame.rgb = rendered.rgb;
  frame.depth_m = rendered.depth_m;
  frame.mask = rendered.object_id;

  // Image motion at the centre over one frame (for the motion blur), from the true poses.
  const Eigen::Vector3d point = frame.world_from_cam * Eigen::Vector3d(0, 0, 2.0);
  const Eigen::Vector3d in_next = path_->WorldFromCam(t + 1.0 / 30.0).Inverse() * point;
  cv::Point2d motion(0, 0);
  if (in_next.z() > 0.1) {
    const Eigen::Vector2d p = camera_.Project(in_next);
    motion = cv::Point2d(p.x() - camera_.cx, p.y() - camera_.cy);
  }
  const uint64_t frame_seed = Mix(options_.seed, 1000003ULL + static_cast<uint64_t>(index));
  ApplyRgbEffects(&frame.rgb, motion, 1.0 + 0.035 * exposure_(t), sensor_, Mix(frame_seed, 1));
  frame.depth_u16 = DepthToSensor(frame.depth_m, sensor_, Mix(frame_seed, 2));
  return frame;
}

std::string SequenceSynth::SceneYaml() const {
  std::ostringstream s;
  s.precision(10);
  s << "# dynorb synthetic sequence: every generation parameter. Regenerate bit-identically with "
       "the\n"
    << "# same dynorb version, photographs and people cut-outs:\n#   " << options_.command_line
    << "\n"
    << "generator: dynorb synth\nsynth_version: " << kSynthVersion << "\n"
    << "preset: " << options_.preset << "\nseed: " << options_.seed << "\nframes: " << num_frames()
    << "\nframes_option: " << options_.frames
    << "\nfps: 30\nstatic_twin: " << (options_.static_twin ? "true" : "false")
    << "\nnoise: " << (options_.noise ? "true" : "false")
    << "\nsupersample: " << options_.supersample << "\npeople: " << sprite_names_.size()
    << "\npeople_dir: '" << options_.people_dir << "'\npeople_sprites: [";
  for (size_t i = 0; i < sprite_names_.size(); ++i) s << (i ? ", " : "") << sprite_names_[i];
  s << "]\nperson_heights_m: [";
  for (size_t i = 0; i < movers_->person_heights().size(); ++i)
    s << (i ? ", " : "") << movers_->person_heights()[i];
  s << "]\ntexture_dir: '" << options_.texture_dir << "'\ntrajectory: '" << options_.trajectory_file
    << "'\ntimestamps: '" << timestamps_source_
    << "'\nscene: office_v1  # 6 x 5 x 3 m room, desks, hall beyond\n"
    << "camera: {fx: " << camera_.fx << ", fy: " << camera_.fy << ", cx: " << camera_.cx
    << ", cy: " << camera_.cy << ", width: " << camera_.width << ", height: " << camera_.height
    << "}\n"
    << "depth_factor: " << sensor_.depth_factor << "\nmax_depth_m: " << sensor_.max_depth_m
    << "\nexposure_fraction: " << sensor_.exposure_fraction
    << "\nobject_ids: {1: person, 2: person, 3: person, 4: pushed box, 5: desk item (static, then "
       "moved)}\n";
  return s.str();
}

SynthReport Synthesize(const SynthOptions& options, const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  options.Validate();
  SequenceWriter::CheckTarget(options.out_dir, options.force);
  SequenceSynth synth(options);  // bad input fails here, before anything is written
  SequenceWriter writer(options.out_dir, options.force);
  const int n = synth.num_frames();
  int threads =
      options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, std::max(1, n));

  std::vector<StampedPose> groundtruth(n);
  std::vector<std::string> object_lines(n);
  std::atomic<int> next{0}, done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  const int cv_threads = cv::getNumThreads();
  cv::setNumThreads(1);  // parallelism is over frames
  auto work = [&]() {
    try {
      std::unique_ptr<Renderer> renderer = synth.MakeRenderer();
      for (int k = next++; k < n && !failed; k = next++) {
        const SynthFrame f = synth.RenderFrame(k, renderer.get());
        writer.WriteFrame(f.time.rgb_ts, f.time.depth_ts, f.rgb, f.depth_u16, f.mask);
        groundtruth[k] = {f.time.rgb_ts, f.world_from_cam};
        std::ostringstream line;
        line.precision(9);
        for (const ObjectState& o : f.objects) {
          const Eigen::Quaterniond& q = o.world_from_object.rotation;
          const Eigen::Vector3d& p = o.world_from_object.translation;
          line << SequenceWriter::Stamp(f.time.rgb_ts) << ' ' << o.id << ' ' << (o.moving ? 1 : 0)
               << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << q.x() << ' ' << q.y()
               << ' ' << q.z() << ' ' << q.w() << '\n';
        }
        object_lines[k] = line.str();
        ++done;
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(work);
  while (done < n && !failed) {
    if (progress) progress(done, n);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (std::thread& t : pool) t.join();
  cv::setNumThreads(cv_threads);
  if (error) std::rethrow_exception(error);
  if (progress) progress(n, n);

  std::vector<double> rgb_ts, depth_ts;
  for (const FrameTime& t : synth.times()) {
    rgb_ts.push_back(t.rgb_ts);
    depth_ts.push_back(t.depth_ts);
  }
  writer.WriteIndex(rgb_ts, depth_ts, groundtruth);
  std::string objects =
      "# moving objects per frame: timestamp id moving tx ty tz qx qy qz qw (world_from_object)\n";
  for (const std::string& l : object_lines) objects += l;
  writer.WriteText("objects.txt", objects);
  writer.WriteText("camera.yaml", SequenceWriter::CameraYaml(synth.camera(), 30.0, 5000.0));
  writer.WriteText("scene.yaml", synth.SceneYaml());
  writer.Commit();

  SynthReport report;
  report.frames = n;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.warnings = synth.warnings();
  return report;
}

}  // namespace dynorb::synth

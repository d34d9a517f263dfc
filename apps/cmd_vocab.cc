// `dynorb vocab`: trains the ORB vocabulary that place recognition uses (relocalisation over the
// whole map) from a set of images, and writes it in dynorb's binary form. The vocabulary built
// into dynorb (config/orb_vocabulary.dynvoc) was made with
//   dynorb vocab --images /usr/share/doc/opencv-doc/examples/data --out
//   config/orb_vocabulary.dynvoc
// (real photographs from Debian's opencv-doc package; docs/place_recognition.md).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command_registry.h"
#include "dynorb/core/error.h"
#include "dynorb/core/timer.h"
#include "dynorb/features/orb_extractor.h"
#include "dynorb/io/atomic_file.h"
#include "dynorb/place_recognition/vocabulary.h"

namespace dynorb {
namespace {

struct VocabCliOptions {
  std::vector<std::string> inputs;
  std::string out_path;
  VocabularyOptions vocabulary;
  int features = 1000;
};

bool IsImageFile(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* e :
       {".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff", ".webp"}) {
    if (ext == e) return true;
  }
  return false;
}

// Image files named on the command line, and the image files (by extension, sorted) directly
// inside the named directories.
std::vector<std::string> ImagePaths(const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::vector<std::string> paths;
  for (const std::string& input : inputs) {
    std::error_code ec;
    if (fs::is_directory(input, ec)) {
      std::vector<std::string> in_dir;
      for (const fs::directory_entry& e : fs::directory_iterator(input, ec)) {
        if (e.is_regular_file() && IsImageFile(e.path())) in_dir.push_back(e.path().string());
      }
      if (in_dir.empty())
        throw InputError(input + ": no image files (.png, .jpg, ...) in this directory");
      std::sort(in_dir.begin(), in_dir.end());
      paths.insert(paths.end(), in_dir.begin(), in_dir.end());
    } else if (fs::is_regular_file(input, ec)) {
      paths.push_back(input);
    } else {
      throw InputError(input + ": no such file or directory");
    }
  }
  return paths;
}

void RunVocab(const VocabCliOptions& cli) {
  cli.vocabulary.Validate();
  OrbOptions orb_options;
  orb_options.n_features = cli.features;
  const OrbExtractor extractor(orb_options);
  AtomicFile out(cli.out_path);  // Checks the output folder before minutes of training.
  const std::vector<std::string> paths = ImagePaths(cli.inputs);
  Stopwatch watch;
  std::vector<cv::Mat> descriptors;
  size_t total = 0;
  for (const std::string& path : paths) {
    const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw InputError(path + ": cannot read this image");
    descriptors.push_back(extractor.DetectAndDescribe(image).descriptors);
    total += static_cast<size_t>(descriptors.back().rows);
  }
  const double extract_s = (watch.ElapsedMs() / 1000.0);
  const Vocabulary vocabulary = Vocabulary::Train(descriptors, cli.vocabulary);
  out.stream() << vocabulary.ToBytes();
  out.Commit();
  std::cout << "wrote " << cli.out_path << ": " << vocabulary.NumWords() << " words (branching "
            << vocabulary.branching() << ", " << vocabulary.levels() << " levels) from " << total
            << " descriptors of " << paths.size() << " images (extraction " << extract_s
            << " s, training " << (watch.ElapsedMs() / 1000.0) - extract_s << " s)\n";
}

const bool kRegistered = RegisterCommand("vocab", 90, [](CLI::App& app) {
  auto opts = std::make_shared<VocabCliOptions>();
  CLI::App* cmd =
      app.add_subcommand("vocab", "Train an ORB vocabulary for place recognition from images");
  cmd->add_option("--images", opts->inputs,
                  "image files, or directories whose image files are used")
      ->required();
  cmd->add_option("--out", opts->out_path, "output vocabulary file")->required();
  VocabularyOptions& v = opts->vocabulary;
  cmd->add_option("--branching", v.branching, "children per node (2..64)")->capture_default_str();
  cmd->add_option("--levels", v.levels, "depth of the words (1..8)")->capture_default_str();
  cmd->add_option("--iterations", v.kmeans_iterations, "k-means iterations per node")
      ->capture_default_str();
  cmd->add_option("--seed", v.seed, "random seed of the k-means++ seeding")
      ->check(NonNegativeInteger())
      ->capture_default_str();
  cmd->add_option(
         "--max-cluster-descriptors", v.max_cluster_descriptors,
         "cluster at most this many descriptors (an even subsample; idf still counts every image)")
      ->check(CLI::Range(100, 100000000))
      ->capture_default_str();
  cmd->add_option("--features", opts->features, "ORB keypoints per image")
      ->check(CLI::Range(10, 100000))
      ->capture_default_str();
  cmd->callback([opts] { RunVocab(*opts); });
});

}  // namespace
}  // namespace dynorb

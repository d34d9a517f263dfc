// `dynorb run --mode fused`: the semantic detector masks and the FAST geometric cues together
// (src/dynorb/dynamic/combined_filter.h). Both YAML sections, `semantic:` and `fast:`, apply.
#include <memory>
#include <utility>
#include <vector>

#include "dynorb/core/error.h"
#include "dynorb/dynamic/combined_filter.h"
#include "mode_fast.h"
#include "mode_semantic.h"

namespace dynorb {
namespace {

class FusedModeFactory : public RunModeFactory {
 public:
  void BindConfig(ConfigSchema* schema) override {
    semantic_.BindConfig(schema);
    fast_.BindConfig(schema);
    schema->Section("fused", "fused mode: semantic + FAST (docs/semantic_mode.md)")
        .Add("fast_only_in_regions", &fast_only_in_regions_,
             "count FAST removals only inside its dynamic regions (isolated votes dropped)")
        .Add("fast_max_removed_fraction", &fast_max_removed_fraction_,
             "FAST evidence is ignored on a frame where it would remove more than this fraction of the keypoints "
             "the detector kept (1: never)")
        .Add("refill", &refill_,
             "detect again outside the fused mask (tracking.refill_filtered) when FAST counts only inside its regions")
        .Add("fast_max_overlap", &fast_max_overlap_,
             "a FAST region lying more than this fraction inside the detector's mask is left to the detector "
             "(its removals do not count; 1: never)")
        .OnLoaded([this] {
          if (!(fast_max_removed_fraction_ > 0.0 && fast_max_removed_fraction_ <= 1.0))
            throw InputError("fused.fast_max_removed_fraction must be in (0, 1]");
          if (!(fast_max_overlap_ >= 0.0 && fast_max_overlap_ <= 1.0))
            throw InputError("fused.fast_max_overlap must be in [0, 1]");
        });
  }
  std::unique_ptr<KeypointFilter> Create(const RunModeContext& context) override {
    std::vector<CombinedFilter::Part> parts;
    parts.push_back({"semantic", semantic_.Create(context)});
    parts.push_back({"fast", fast_.Create(context), fast_only_in_regions_, fast_max_removed_fraction_, fast_max_overlap_});
    return std::make_unique<CombinedFilter>(std::move(parts), refill_);
  }

 private:
  // FAST's defaults (LK on the 400-point subset) except a new region's seeds: 4 instead of 3
  // (session 33, three runs of the 24 sequences: mean ATE -5.1 % on the 300-frame cuts, -1.4 % at
  // full length; the `fast:` key still overrides it). Until session 6 fused tracked every
  // keypoint (v1 data: 1.29 with all, 1.53 with 400); with fast_max_overlap and refill the subset
  // is as good and cheaper (v2 data, 12 sequences: 1.26 with 400, 1.29 with all).
  // The residual veto too (session 52, the 12 cuts and their twins x 3 replicates: mean ATE
  // 3.209 -> 3.204 mm, walking_halfsphere s9 1.31 -> 1.29, <= 1.3 on 12 of 12; FAST's quiet
  // schedule with it: 3.236 mm, worst 1.35, not adopted).
  static FastOptions FastDefaults() {
    FastOptions o;
    o.region_min_seeds = 4;
    o.residual_static_veto = true;
    return o;
  }
  SemanticModeFactory semantic_;
  FastModeFactory fast_{FastDefaults()};
  bool fast_only_in_regions_ = true;  // Measured: FAST precision 0.46 -> 0.54 on walking_xyz.
  double fast_max_removed_fraction_ = 0.1;  // Measured: walking_rpy 14.2 -> 7.9 mm, no lost episodes.
  // Measured together (v2 data, 12 walking sequences, 2026-12-02): mean ratio 1.60 -> 1.29, mean
  // ATE 8.21 -> 6.22 mm; refill alone 1.39, overlap 0.5 alone 1.40 (docs/semantic_mode.md).
  double fast_max_overlap_ = 0.5;
  bool refill_ = true;
};

const bool kRegistered = RegisterRunMode(
    "fused", "semantic detector masks and FAST geometric cues together (a keypoint must pass both)",
    [] { return std::make_unique<FusedModeFactory>(); });

}  // namespace
}  // namespace dynorb

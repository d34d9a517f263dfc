#include "dynorb/synth/office.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/error.h"
#include "dynorb/synth/procedural.h"

namespace dynorb::synth {
namespace {

using V = Eigen::Vector3d;

TextureMaker Solid(cv::Scalar bgr, double amplitude, uint64_t seed) {
  return [=](cv::Size s) {
    cv::RNG rng(seed);
    return NoisyColor(s, bgr, amplitude, 40.0, rng);
  };
}

TextureMaker Resized(const cv::Mat& photo) {
  return [photo](cv::Size s) {
    cv::Mat out;
    cv::resize(photo, out, s, 0, 0, cv::INTER_AREA);
    return out;
  };
}

// A chair of light wood on a five-star-like base, seat centre (x, y).
void AddChair(SceneBuilder& b, double x, double y, uint64_t seed) {
  const TextureMaker wood = [seed](cv::Size s) {
    cv::RNG rng(seed);
    return Wood(s, {70, 160, 215}, rng);
  };
  const TextureMaker metal = Solid({60, 60, 62}, 0.1, seed + 1);
  b.AddBox(V(x - 0.22, y - 0.22, 0.44), V(x + 0.22, y + 0.22, 0.48), wood, 300);
  b.AddBox(V(x - 0.2, y + 0.19, 0.56), V(x + 0.2, y + 0.23, 0.9), wood, 300);
  b.AddBox(V(x - 0.02, y + 0.2, 0.48), V(x + 0.02, y + 0.22, 0.56), metal, 200);
  b.AddBox(V(x - 0.025, y - 0.025, 0.08), V(x + 0.025, y + 0.025, 0.44), metal, 200);
  b.AddBox(V(x - 0.3, y - 0.02, 0.03), V(x + 0.3, y + 0.02, 0.08), metal, 200);
  b.AddBox(V(x - 0.02, y - 0.3, 0.03), V(x + 0.02, y + 0.3, 0.08), metal, 200);
  b.AddOccluder(x - 0.22, y - 0.22, x + 0.22, y + 0.22, 0.44);
}

// A desk [x0,x1] x [y0,y1] with its top at z_top, four metal legs and a modesty panel.
void AddDesk(SceneBuilder& b, double x0, double y0, double x1, double y1, double z_top,
             uint64_t seed) {
  const TextureMaker top = Solid({196, 204, 206}, 0.05, seed);
  const TextureMaker metal = Solid({175, 178, 180}, 0.06, seed + 1);
  b.AddBox(V(x0, y0, z_top - 0.03), V(x1, y1, z_top), top, 250);
  for (double x : {x0 + 0.03, x1 - 0.07})
    for (double y : {y0 + 0.03, y1 - 0.07})
      b.AddBox(V(x, y, 0), V(x + 0.04, y + 0.04, z_top - 0.03), metal, 200);
  b.AddBox(V(x0 + 0.07, y1 - 0.06, 0.3), V(x1 - 0.07, y1 - 0.04, z_top - 0.03),
           Solid({150, 170, 185}, 0.1, seed + 2), 150);
}

// A monitor centred at x on the desk, its screen facing -y, showing `screen` (dark when empty).
void AddMonitor(SceneBuilder& b, double x, double y, double z, double w, double h,
                const cv::Mat& screen, uint64_t seed) {
  const TextureMaker plastic = Solid({38, 38, 40}, 0.08, seed);
  b.AddBox(V(x - 0.11, y - 0.06, z), V(x + 0.11, y + 0.1, z + 0.015), plastic, 300);
  b.AddBox(V(x - 0.025, y + 0.03, z + 0.015), V(x + 0.025, y + 0.06, z + 0.12), plastic, 300);
  const double bottom = z + 0.1;
  b.AddBox(V(x - w / 2, y, bottom), V(x + w / 2, y + 0.045, bottom + h), plastic, 300);
  const double bezel = 0.018;
  const V origin(x - w / 2 + bezel, y - 0.0015, bottom + h - bezel);
  const V u(w - 2 * bezel, 0, 0), v(0, 0, -(h - 2 * bezel));
  if (screen.empty()) {
    b.AddRect(
        origin, u, v,
        [seed](cv::Size s) {
          cv::RNG rng(seed + 7);
          cv::Mat img = NoisyColor(s, {30, 28, 26}, 0.25, s.width / 3.0,
                                   rng);  // switched-off screen, reflections
          return img;
        },
        500);
  } else {
    b.AddPicture(origin, u, v, screen);
  }
}

}  // namespace

const std::vector<std::string>& OfficePhotoNames() {
  static const std::vector<std::string> names = {
      "building.jpg",  "graf1.png", "starry_night.jpg", "fruits.jpg", "baboon.jpg",
      "HappyFish.jpg", "home.jpg",  "notes.png",        "box.png",    "board.jpg",
      "smarties.png",  "stuff.jpg", "aero1.jpg"};
  return names;
}

PhotoLibrary::PhotoLibrary(const std::string& dir, bool strict) {
  if (!dir.empty() && !std::filesystem::is_directory(dir)) {
    if (strict) throw InputError("texture directory not found: " + dir);
  }
  cv::RNG rng(4711);
  for (const std::string& name : OfficePhotoNames()) {
    cv::Mat img;
    const std::filesystem::path path = std::filesystem::path(dir) / name;
    if (!dir.empty() && std::filesystem::is_regular_file(path))
      img = cv::imread(path.string(), cv::IMREAD_COLOR);
    if (img.empty()) {
      if (strict)
        throw InputError("texture file missing or unreadable: " +
                         (std::filesystem::path(dir) / name).string());
      missing_.push_back(name);
      img = PseudoPhoto(cv::Size(512, 384), rng);
    }
    photos_[name] = img;
  }
}

cv::Mat PhotoLibrary::Get(const std::string& name) const { return photos_.at(name); }

void BuildOffice(uint64_t seed, const PhotoLibrary& photos, Office* office) {
  Scene& scene = office->scene;
  SceneBuilder b(&scene);
  cv::RNG rng(seed ^ 0x0FF1CEULL);
  auto jitter = [&rng](double amount) { return rng.uniform(-amount, amount); };
  auto next_seed = [&rng]() { return static_cast<uint64_t>(rng.next()); };

  for (double x : {1.5, 4.5})
    for (double y : {1.5, 3.8}) b.AddLight(V(x, y, 2.95), 0.55);
  b.AddLight(V(3.0, 8.0, 6.5), 1.2);
  const double desk_z = 0.72;
  office->desk_top_z = desk_z;
  b.AddOccluder(0.9, 3.8, 2.5, 4.58, desk_z);
  b.AddOccluder(2.7, 3.8, 4.3, 4.58, desk_z);
  b.AddOccluder(5.45, 1.2, 5.98, 2.2, 1.1);

  // Room shell (front sides face the inside).
  const uint64_t s_floor = next_seed();
  b.AddRect(
      V(0, 4.6, 0), V(6, 0, 0), V(0, -4.6, 0),
      [s_floor](cv::Size s) {
        cv::RNG r(s_floor);
        return Carpet(s, {128, 132, 134}, r);
      },
      200);
  const uint64_t s_ceiling = next_seed();
  b.AddRect(
      V(0, 0, 3), V(6, 0, 0), V(0, 5, 0),
      [s_ceiling](cv::Size s) {
        cv::RNG r(s_ceiling);
        return CeilingTiles(s, 120, r);
      },
      120);
  b.AddRect(V(0, 0, 3), V(0, 5, 0), V(0, 0, -3), Solid({200, 212, 218}, 0.06, next_seed()), 120);
  b.AddRect(V(6, 5, 3), V(0, -5, 0), V(0, 0, -3), Solid({205, 214, 218}, 0.06, next_seed()), 120);
  b.AddRect(V(6, 0, 3), V(-6, 0, 0), V(0, 0, -3), Solid({200, 210, 215}, 0.06, next_seed()), 120);
  // Door in the wall behind the camera, a skirting board along the side walls.
  const uint64_t s_door = next_seed();
  b.AddRect(
      V(4.9, 0.005, 2.05), V(-0.95, 0, 0), V(0, 0, -2.05),
      [s_door](cv::Size s) {
        cv::RNG r(s_door);
        return Wood(s, {80, 120, 160}, r);
      },
      150);

  // Partition wall with panel seams, posters; white panels and the hall beyond it.
  const uint64_t s_part = next_seed();
  const TextureMaker partition = [s_part](cv::Size s) {
    cv::RNG r(s_part);
    cv::Mat img = NoisyColor(s, {118, 168, 196}, 0.1, 30.0, r);
    const int panel = std::max(8, s.width / 5);
    for (int x = panel; x < s.width; x += panel)
      cv::line(img, {x, 0}, {x, s.height}, {80, 115, 140}, 3);
    cv::rectangle(img, {0, 0}, {s.width, 6}, {150, 150, 150}, cv::FILLED);
    return img;
  };
  b.AddBox(V(0, 4.6, 0), V(6, 4.66, 1.45), partition, 220);
  b.AddPicture(V(2.45 + jitter(0.03), 4.597, 1.38), V(0.42, 0, 0), V(0, 0, -0.55),
               photos.Get("graf1.png"));
  b.AddPicture(V(4.45, 4.597, 1.3 + jitter(0.03)), V(0.6, 0, 0), V(0, 0, -0.45),
               photos.Get("starry_night.jpg"));
  b.AddPicture(V(0.25, 4.597, 1.25), V(0.5, 0, 0), V(0, 0, -0.38), photos.Get("fruits.jpg"));
  b.AddPicture(V(5.35, 4.597, 1.2), V(0.45, 0, 0), V(0, 0, -0.6), photos.Get("board.jpg"));
  const uint64_t s_white = next_seed();
  b.AddBox(
      V(0.3, 5.2, 1.45), V(5.7, 5.25, 2.1),
      [s_white](cv::Size s) {
        cv::RNG r(s_white);
        cv::Mat img = NoisyColor(s, {222, 226, 228}, 0.04, 40.0, r);
        const int panel = std::max(8, s.width / 6);
        for (int x = 0; x < s.width; x += panel)
          cv::rectangle(img, {x, 0}, {x + panel, s.height - 1}, {150, 150, 155}, 3);
        return img;
      },
      120);
  b.AddPicture(V(-5, 11, 7), V(16, 0, 0), V(0, 0, -7), photos.Get("building.jpg"));
  b.AddRect(V(-5, 11, 0), V(16, 0, 0), V(0, -6.34, 0), Solid({150, 155, 160}, 0.2, next_seed()), 50,
            2.0);
  const uint64_t s_hall = next_seed();
  b.AddRect(
      V(-5, 4.66, 7), V(16, 0, 0), V(0, 6.34, 0),
      [s_hall](cv::Size s) {
        cv::RNG r(s_hall);
        cv::Mat img = NoisyColor(s, {120, 135, 150}, 0.15, 20.0, r);
        for (int x = 0; x < s.width; x += 25) cv::line(img, {x, 0}, {x, s.height}, {60, 70, 80}, 3);
        for (int y = 0; y < s.height; y += 60)
          cv::line(img, {0, y}, {s.width, y}, {210, 220, 225}, 4);
        return img;
      },
      50, 2.0);
  b.AddRect(V(-5, 4.66, 7), V(0, 6.34, 0), V(0, 0, -7), Solid({170, 180, 185}, 0.2, next_seed()),
            50, 2.0);
  b.AddRect(V(11, 11, 7), V(0, -6.34, 0), V(0, 0, -7), Solid({170, 180, 185}, 0.2, next_seed()), 50,
            2.0);

  // Desks with monitors, keyboards, papers, books.
  AddDesk(b, 0.9, 3.8, 2.5, 4.58, desk_z, next_seed());
  AddDesk(b, 2.7, 3.8, 4.3, 4.58, desk_z, next_seed());
  AddMonitor(b, 1.7 + jitter(0.05), 4.28, desk_z, 0.56, 0.34, cv::Mat(), next_seed());
  AddMonitor(b, 3.55 + jitter(0.05), 4.25, desk_z, 0.62, 0.38, photos.Get("home.jpg"), next_seed());
  const uint64_t s_keys = next_seed();
  const TextureMaker keys = [s_keys](cv::Size s) {
    cv::RNG r(s_keys);
    return Keyboard(s, r);
  };
  const TextureMaker dark = Solid({50, 50, 54}, 0.1, next_seed());
  for (double kx : {1.48 + jitter(0.04), 3.3 + jitter(0.04)}) {
    const double ky = 3.92 + jitter(0.03);
    b.AddBox(V(kx, ky, desk_z), V(kx + 0.44, ky + 0.15, desk_z + 0.022), dark, 800, keys);
    b.AddBox(V(kx + 0.52, ky + 0.04, desk_z), V(kx + 0.58, ky + 0.1, desk_z + 0.03), dark, 400);
  }
  const uint64_t s_paper = next_seed();
  b.AddRect(
      V(2.05, 4.2, desk_z + 0.0008), V(0.21, 0, 0), V(0, -0.297, 0),
      [s_paper](cv::Size s) {
        cv::RNG r(s_paper);
        return Scribbles(s, {235, 238, 240}, r);
      },
      900);
  const uint64_t s_books = next_seed();
  const TextureMaker spines = [s_books](cv::Size s) {
    cv::RNG r(s_books);
    return BookSpines(s, r);
  };
  b.AddBox(V(2.85, 4.1, desk_z), V(3.05, 4.4, desk_z + 0.12), spines, 500,
           Resized(photos.Get("aero1.jpg")));
  b.AddBox(V(4.05, 3.95, desk_z), V(4.12, 4.02, desk_z + 0.24),
           Solid({60, 140, 40}, 0.2, next_seed()), 400);
  AddChair(b, 1.75 + jitter(0.1), 3.55, next_seed());
  AddChair(b, 3.45 + jitter(0.1), 3.5, next_seed());

  // Shelf with books against the left wall, whiteboard and a pinboard photo.
  const TextureMaker shelf_wood = [s = next_seed()](cv::Size sz) {
    cv::RNG r(s);
    return Wood(sz, {150, 180, 200}, r);
  };
  b.AddBox(V(0.02, 1.5, 0), V(0.42, 1.53, 1.9), shelf_wood, 200);
  b.AddBox(V(0.02, 2.87, 0), V(0.42, 2.9, 1.9), shelf_wood, 200);
  b.AddRect(V(0.021, 1.53, 1.9), V(0, 1.34, 0), V(0, 0, -1.9), shelf_wood, 200);
  for (double z : {0.02, 0.47, 0.92, 1.37, 1.86}) {
    b.AddBox(V(0.02, 1.53, z), V(0.42, 2.87, z + 0.025), shelf_wood, 200);
    if (z > 1.8) continue;
    const uint64_t s_row = next_seed();
    const double h = 0.26 + jitter(0.04);
    b.AddBox(
        V(0.05, 1.56, z + 0.025), V(0.33 + jitter(0.04), 2.84, z + 0.025 + h),
        [s_row](cv::Size sz) {
          cv::RNG r(s_row);
          return BookSpines(sz, r);
        },
        400);
  }
  const uint64_t s_board = next_seed();
  b.AddRect(
      V(0.01, 3.1, 2.0), V(0, 1.3, 0), V(0, 0, -0.9),
      [s_board](cv::Size s) {
        cv::RNG r(s_board);
        cv::Mat img = Scribbles(s, {238, 240, 240}, r);
        cv::rectangle(img, {0, 0}, {s.width - 1, s.height - 1}, {150, 150, 150}, 6);
        return img;
      },
      400);
  b.AddPicture(V(0.012, 3.25, 1.55), V(0, 1.0, 0), V(0, 0, -0.13), photos.Get("notes.png"));
  b.AddPicture(V(0.01, 0.5, 1.8), V(0, 0.7, 0), V(0, 0, -0.5), photos.Get("stuff.jpg"));

  // Right wall: posters, a metal cabinet, cardboard boxes.
  b.AddPicture(V(5.995, 3.3, 1.9), V(0, -0.6, 0), V(0, 0, -0.6), photos.Get("baboon.jpg"));
  b.AddPicture(V(5.995, 4.35, 1.75), V(0, -0.7, 0), V(0, 0, -0.5), photos.Get("HappyFish.jpg"));
  const uint64_t s_cab = next_seed();
  b.AddBox(
      V(5.45, 1.2, 0), V(5.98, 2.2, 1.1),
      [s_cab](cv::Size s) {
        cv::RNG r(s_cab);
        cv::Mat img = NoisyColor(s, {150, 150, 146}, 0.06, 30.0, r);
        for (int k = 1; k < 4; ++k) {
          const int y = k * s.height / 4;
          cv::line(img, {0, y}, {s.width, y}, {90, 90, 90}, 2);
          cv::rectangle(img, {s.width / 2 - 20, y - 30}, {s.width / 2 + 20, y - 22}, {60, 60, 60},
                        cv::FILLED);
        }
        return img;
      },
      200);
  const uint64_t s_box = next_seed();
  const TextureMaker cardboard = [s_box](cv::Size s) {
    cv::RNG r(s_box);
    return Cardboard(s, r);
  };
  b.AddBox(V(5.2, 3.0, 0), V(5.7, 3.5, 0.45), cardboard, 250);
  b.AddBox(V(5.27, 3.06, 0.45), V(5.62, 3.42, 0.75), cardboard, 250);

  // Rigid movers (own frames, origin at the bottom centre).
  const uint64_t s_push = next_seed();
  const cv::Mat label = photos.Get("box.png");
  office->pushed_box = b.MakeBox(
      V(-0.25, -0.2, 0), V(0.25, 0.2, 0.45),
      [s_push, label](cv::Size s) {
        cv::RNG r(s_push);
        cv::Mat img = Cardboard(s, r);
        cv::Mat small;
        cv::resize(label, small, cv::Size(s.width / 2, s.height / 2), 0, 0, cv::INTER_AREA);
        small.copyTo(img(cv::Rect(s.width / 4, s.height / 4, small.cols, small.rows)));
        return img;
      },
      300, {}, 0);
  office->pushed_box_start = V(1.0, 2.7, 0);
  office->desk_item = b.MakeBox(V(-0.1, -0.06, 0), V(0.1, 0.06, 0.28),
                                Resized(photos.Get("smarties.png")), 600, {}, 0);
  office->desk_item_start = V(2.3, 4.38, desk_z);

  office->camera_anchor = V(3.0, 1.0, 1.4);
  office->look_at = V(2.8, 4.4, 0.85);
  office->walk_x0 = 0.7;
  office->walk_x1 = 5.3;
  office->walk_y0 = 1.75;
  office->walk_y1 = 3.2;
}

}  // namespace dynorb::synth

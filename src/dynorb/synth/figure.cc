#include "dynorb/synth/figure.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "dynorb/core/angles.h"
#include "dynorb/synth/procedural.h"

namespace dynorb::synth {
namespace {

// A limb: a tapered quadrilateral from `from` along angle `angle` (0 = straight down).
std::vector<cv::Point> Limb(cv::Point2d from, double length, double angle, double w_top,
                            double w_bottom) {
  const cv::Point2d dir(std::sin(angle), std::cos(angle));
  const cv::Point2d side(dir.y, -dir.x);
  const cv::Point2d to = from + dir * length;
  std::vector<cv::Point> poly;
  for (const cv::Point2d& p : {from + side * (w_top / 2), to + side * (w_bottom / 2),
                               to - side * (w_bottom / 2), from - side * (w_top / 2)})
    poly.emplace_back(cvRound(p.x * 16), cvRound(p.y * 16));
  return poly;
}

void Paint(cv::Mat& colour, cv::Mat& alpha, const cv::Mat& texture,
           const std::vector<cv::Point>& poly) {
  cv::Mat part = cv::Mat::zeros(alpha.size(), CV_8U);
  cv::fillConvexPoly(part, poly, 255, cv::LINE_AA, 4);
  texture.copyTo(colour, part > 0);
  cv::max(alpha, part, alpha);
}

}  // namespace

std::vector<cv::Mat> MakeFigureSprites(uint64_t seed, int phases, int height_px) {
  cv::RNG rng(seed * 0x2545F4914F6CDD1DULL + 3);
  const int h = height_px, w = static_cast<int>(0.46 * h);
  const cv::Size size(w, h);
  const cv::Scalar shirt_colour(rng.uniform(40, 200), rng.uniform(40, 200), rng.uniform(40, 200));
  const cv::Mat shirt = Plaid(size, shirt_colour, rng);
  const cv::Mat trousers =
      Denim(size, cv::Scalar(rng.uniform(90, 140), rng.uniform(60, 90), rng.uniform(40, 70)), rng);
  const cv::Mat skin =
      NoisyColor(size, cv::Scalar(120, 150, 205) * rng.uniform(0.7, 1.05), 0.06, 20.0, rng);
  const cv::Mat hair =
      NoisyColor(size, cv::Scalar(30, 45, 60) * rng.uniform(0.6, 1.8), 0.3, 6.0, rng);
  const cv::Mat shoes = NoisyColor(size, cv::Scalar(35, 35, 38), 0.2, 10.0, rng);
  const double u = h / 8.0, cx = w / 2.0;
  // Cylindrical shading across the body.
  cv::Mat shade(size, CV_32FC3);
  for (int x = 0; x < w; ++x) {
    const double r = (x - cx) / (1.3 * u);
    const float f =
        static_cast<float>(0.7 + 0.35 * std::sqrt(std::max(0.0, 1.0 - std::min(1.0, r * r))));
    shade.col(x).setTo(cv::Scalar(f, f, f));
  }
  std::vector<cv::Mat> sprites;
  for (int k = 0; k < phases; ++k) {
    const double phase = 2.0 * kPi * k / phases;
    const double leg = 0.35 * std::sin(phase), arm = -0.3 * std::sin(phase);
    cv::Mat colour(size, CV_8UC3, cv::Scalar(0, 0, 0)), alpha = cv::Mat::zeros(size, CV_8U);
    Paint(colour, alpha, shirt,
          Limb({cx - 0.95 * u, 0.17 * h}, 0.36 * h, -arm - 0.08, 0.38 * u, 0.3 * u));
    for (int side : {-1, 1}) {
      const double a = side * leg;
      const cv::Point2d hip(cx + side * 0.38 * u, 0.52 * h);
      Paint(colour, alpha, trousers, Limb(hip, 0.45 * h, a, 0.62 * u, 0.42 * u));
      const cv::Point2d ankle = hip + cv::Point2d(std::sin(a), std::cos(a)) * (0.45 * h);
      Paint(colour, alpha, shoes,
            Limb(ankle - cv::Point2d(0, 0.01 * h), 0.035 * h, a, 0.5 * u, 0.55 * u));
    }
    std::vector<cv::Point> torso = {{cvRound((cx - 1.0 * u) * 16), cvRound(0.15 * h * 16)},
                                    {cvRound((cx + 1.0 * u) * 16), cvRound(0.15 * h * 16)},
                                    {cvRound((cx + 0.78 * u) * 16), cvRound(0.55 * h * 16)},
                                    {cvRound((cx - 0.78 * u) * 16), cvRound(0.55 * h * 16)}};
    Paint(colour, alpha, shirt, torso);
    Paint(colour, alpha, shirt,
          Limb({cx + 0.95 * u, 0.17 * h}, 0.36 * h, arm + 0.08, 0.38 * u, 0.3 * u));
    for (int side : {-1, 1}) {
      const double a = side * arm + side * 0.08;
      const cv::Point2d wrist = cv::Point2d(cx + side * 0.95 * u, 0.17 * h) +
                                cv::Point2d(std::sin(a), std::cos(a)) * (0.36 * h);
      cv::Mat hand = cv::Mat::zeros(size, CV_8U);
      cv::circle(hand, wrist, static_cast<int>(0.2 * u), 255, cv::FILLED, cv::LINE_AA);
      skin.copyTo(colour, hand > 0);
      cv::max(alpha, hand, alpha);
    }
    cv::Mat head = cv::Mat::zeros(size, CV_8U);
    cv::ellipse(head, cv::Point(cvRound(cx), cvRound(0.075 * h)),
                cv::Size(cvRound(0.42 * u), cvRound(0.52 * u)), 0, 0, 360, 255, cv::FILLED,
                cv::LINE_AA);
    cv::rectangle(head, cv::Point(cvRound(cx - 0.18 * u), cvRound(0.12 * h)),
                  cv::Point(cvRound(cx + 0.18 * u), cvRound(0.16 * h)), 255, cv::FILLED);
    skin.copyTo(colour, head > 0);
    cv::max(alpha, head, alpha);
    cv::Mat top = cv::Mat::zeros(size, CV_8U);
    cv::ellipse(top, cv::Point(cvRound(cx), cvRound(0.06 * h)),
                cv::Size(cvRound(0.45 * u), cvRound(0.4 * u)), 0, 180, 360, 255, cv::FILLED,
                cv::LINE_AA);
    hair.copyTo(colour, top > 0);
    // Eyes and mouth.
    cv::circle(colour, cv::Point(cvRound(cx - 0.15 * u), cvRound(0.075 * h)),
               std::max(1, cvRound(0.05 * u)), {30, 30, 30}, cv::FILLED);
    cv::circle(colour, cv::Point(cvRound(cx + 0.15 * u), cvRound(0.075 * h)),
               std::max(1, cvRound(0.05 * u)), {30, 30, 30}, cv::FILLED);
    cv::line(colour, cv::Point(cvRound(cx - 0.12 * u), cvRound(0.1 * h)),
             cv::Point(cvRound(cx + 0.12 * u), cvRound(0.1 * h)), {60, 60, 120},
             std::max(1, cvRound(0.04 * u)));
    cv::Mat shaded;
    colour.convertTo(shaded, CV_32FC3);
    shaded = shaded.mul(shade);
    shaded.convertTo(colour, CV_8UC3);
    cv::Mat bgra;
    std::vector<cv::Mat> channels;
    cv::split(colour, channels);
    channels.push_back(alpha);
    cv::merge(channels, bgra);
    sprites.push_back(bgra);
  }
  return sprites;
}

}  // namespace dynorb::synth

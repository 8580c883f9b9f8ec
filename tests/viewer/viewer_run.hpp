#pragma once
// The built sailshape-viewer run as a user would, under a private X server
// (xvfb-run), and its screenshot read back: the window's fixed layout and the
// colours the panels draw.
#include <gtest/gtest.h>
#include <stb_image.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <string>

#include "viewer_fixture.hpp"

namespace sailshape::viewer::run_test {

inline constexpr int kWidth = 1600, kHeight = 1000;

struct ViewerRun {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline ViewerRun runViewer(const test::TempDir& dir, const std::string& args, int width = kWidth, int height = kHeight) {
  std::string launcher;
  if (std::system("command -v xvfb-run >/dev/null 2>&1") == 0)
    launcher = "xvfb-run -a -s '-screen 0 1920x1200x24' ";  // a private server even when DISPLAY is set
  else if (!std::getenv("DISPLAY"))
    ADD_FAILURE() << "neither xvfb-run nor a DISPLAY: install xvfb (scripts/setup)";
  const std::string out = dir.file("stdout.txt"), err = dir.file("stderr.txt");
  const std::string cmd = launcher + quote(SAILSHAPE_VIEWER_BIN) + " " + args + " --width " + std::to_string(width) +
                          " --height " + std::to_string(height) + " </dev/null >" + quote(out) + " 2>" + quote(err);
  const int status = std::system(cmd.c_str());
  ViewerRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

struct Image {
  int width = 0, height = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> rgb{nullptr, stbi_image_free};
  const unsigned char* at(int x, int y) const { return rgb.get() + 3 * (static_cast<size_t>(y) * width + x); }
};

inline Image load(const std::string& path) {
  Image img;
  int channels = 0;
  img.rgb.reset(stbi_load(path.c_str(), &img.width, &img.height, &channels, 3));
  return img;
}

struct Rect {
  int x0, y0, x1, y1;
};

// The fixed layout of a 1600 × 1000 window (viewer/app.cpp): toolbar 40 px, status
// bar 28 px, browser 300 px on the left, analysis panel 440 px on the right, the
// 3D view over 64 % of the middle height and the plots below; a few pixels in
// from every edge and below the panel title bars.
inline const Rect kView{310, 70, 1150, 626};
inline const Rect kPlots{310, 690, 1150, 960};
inline const Rect kBrowser{6, 62, 294, 600};
inline const Rect kAnalysis{1166, 62, 1594, 900};
// The scalar bar: 90–98 % of the view's width, 12–88 % of its height.
inline const Rect kScalarBar{1080, 140, 1140, 560};

using Pixel = std::function<bool(int r, int g, int b)>;

inline size_t count(const Image& img, const Rect& r, const Pixel& is) {
  size_t n = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) {
      const unsigned char* p = img.at(x, y);
      if (is(p[0], p[1], p[2])) ++n;
    }
  return n;
}

inline double area(const Rect& r) { return double(r.x1 - r.x0) * (r.y1 - r.y0); }

// The design's blue (64, 140, 255) and the flying shape's red (220, 34, 26), shaded.
inline const Pixel kBlue = [](int r, int g, int b) { return b > 170 && b > r + 80 && b > g + 40; };
inline const Pixel kRed = [](int r, int g, int b) { return r > 110 && r > 2 * g && r > 2 * b; };
inline const Pixel kText = [](int r, int g, int b) { return r > 170 && g > 170 && b > 170; };
inline const Pixel kErrorText = [](int r, int g, int b) { return r > 200 && g > 80 && g < 160 && b < 160 && r > g + 60; };

}  // namespace sailshape::viewer::run_test

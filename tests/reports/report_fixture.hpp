#pragma once
// The reports' test fixture: a database of a test of known trim steps (the
// generator's design with its twist opened and camber deepened step by step),
// and poppler's pdftotext / pdfinfo / pdftoppm read back as text, words with
// their boxes, and pixels.
#include <gtest/gtest.h>

#include <regex>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/design/sail_generator.hpp"
#include "database/catalog.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"
#include "reports/trim_report.hpp"
#include "tests/database/db_fixture.hpp"

namespace sailshape::report_test {

using test::TempDir;

inline constexpr int kSteps = 3, kSections = 8;
inline const char* const kSail = "Grand-voile Été";
// Long enough to meet the page titles in the header band unless they make room.
inline const char* const kBoat = "Øresund Flyer, 1:3.6 tunnel model of the 36 ft cruiser-racer";
inline const char* const kCampaign = "Régates de Côte Bleue";
inline const char* const kTest = "twist sweep";

// Step k's flying shape: the design with its sheet eased, twist opened by
// 1.5°·k over the whole height plus 1.5°·k more at the head, and 0.5 % deeper per step.
inline SailDesign flyingDesign(const SailDesign& design, int k) {
  SailDesign d = design;
  for (auto& s : d.stations) {
    s.twist_deg += 1.5 * k * (1 + s.fraction);
    s.camber_pct += 0.5 * k;
  }
  return d;
}

inline double round2(double v) { return std::round(v * 100) / 100; }
inline double round1(double v) { return std::round(v * 10) / 10; }

// A flying section of step k at fraction f: the generator's known parameters,
// rounded as the report prints them, so the PDF must show exactly these.
inline nlohmann::json flyingSection(const SailSurface& surface, double f, int k) {
  const KnownSection known = surface.section(f);
  nlohmann::json s = {{"fraction", f},
                      {"chord_m", round2(known.chord_m)},
                      {"camber_pct", round2(known.camber_pct)},
                      {"draft_pct", round1(known.draft_pct)},
                      {"twist_deg", round1(known.twist_deg)},
                      {"twist_rel_deg", 0.0},
                      {"entry_deg", round1(known.entry_deg)},
                      {"exit_deg", round1(known.exit_deg)},
                      {"plane_tilt_deg", 0.0},
                      {"converged", true}};
  // SPEC §3: σ ≈ 4 mm on chords of 2–4 m gives ≈ 0.1–0.2 % camber, ≈ 0.1° twist.
  s["uncertainty"] = {{"chord_m", 0.006},     {"camber_pct", 0.13 + 0.01 * k}, {"draft_pct", 0.9},
                      {"twist_deg", 0.2},     {"twist_rel_deg", 0.3},          {"entry_deg", 1.1},
                      {"exit_deg", 1.3}};
  nlohmann::json curve = nlohmann::json::array();
  for (int i = 0; i <= 40; ++i) {
    const Vec3 p = surface.at(f, i / 40.0);
    curve.push_back({p.x(), p.y(), p.z()});
  }
  s["curve"] = curve;
  return s;
}

// Step k's outline as `sailshape analyze --json` stores it: the luff 2 cm longer per
// step (halyard), the rest as printed by the report (3 and 2 decimals), each with a σ.
inline void flyingOutline(nlohmann::json& doc, int k) {
  doc["sail"] = {{"luff_length_m", 10.012 + 0.02 * k}, {"leech_length_m", 10.481}, {"foot_length_m", 3.597},
                 {"area_m2", 18.34 - 0.05 * k}, {"beam_footprint_m", 0.021 + 0.01 * k}};
  doc["sail"]["uncertainty"] = {{"luff_length_m", 0.004}, {"leech_length_m", 0.005}, {"foot_length_m", 0.003},
                                {"area_m2", 0.02}};
  doc["luff"] = {{"lufa_sag_pct", 0.85 + 0.1 * k}, {"lufa_position_pct", 48.0}, {"lusw_sag_pct", -0.31},
                 {"lusw_position_pct", 55.0}};
  doc["luff"]["uncertainty"] = {{"lufa_sag_pct", 0.03}, {"lufa_position_pct", 6.0}, {"lusw_sag_pct", 0.04},
                                {"lusw_position_pct", 9.0}};
}

struct Fixture {
  TempDir dir;
  std::string db_path = dir.file("trim.sailshape");
  SailDesign design = exampleDesign(SailType::Main);
  std::vector<int64_t> scan_ids;
  std::vector<nlohmann::json> docs;

  Fixture() {
    Database db = openSailDatabase(db_path);
    const Mesh mesh = generateSailMesh(design);
    upsertSail(db, {kSail, "mainsail", "M", "Voilerie Lætitia", "v3", kBoat}, &mesh);
    for (int k = 0; k < kSteps; ++k) {
      const SailSurface surface(flyingDesign(design, k));
      nlohmann::json doc;
      doc["sections"] = nlohmann::json::array();
      for (int i = 1; i <= kSections; ++i) doc["sections"].push_back(flyingSection(surface, i / 9.0, k));
      flyingOutline(doc, k);
      ImportMetadata meta;
      meta.campaign = kCampaign;
      meta.session = "day 1";
      meta.sail = kSail;
      meta.boat = kBoat;
      meta.test = kTest;
      meta.trim_step = k + 1;
      meta.awa_deg = 26.0 + 2 * k;
      meta.aws_m_s = 6.5;
      meta.drive_n = 410.0 + 25 * k;
      meta.side_n = 980.0 - 40 * k;
      meta.heel_moment_nm = 2600.0 - 90 * k;
      meta.controls = {{"sheet", 1.25 - 0.05 * k}, {"traveller", 0.1 * k}};
      meta.scanned_at = "2026-06-1" + std::to_string(k) + "T10:30:00Z";
      scan_ids.push_back(importScan(db, meta, &doc).scan_id);
      docs.push_back(doc);
    }
  }

  TrimReportParams params(const std::string& out) const {
    TrimReportParams p;
    p.db_path = db_path;
    p.test = kTest;
    p.out_path = dir.file(out);
    return p;
  }
};

// One fixture for the suite: the database is read-only to every test.
inline Fixture& fixture() {
  static Fixture f;
  return f;
}

inline std::string run(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

inline std::string pdfText(const std::string& pdf) { return run("pdftotext -layout '" + pdf + "' - 2>/dev/null"); }

// Pairs of words in the header band (top 34 pt) of every page whose boxes overlap, as "page: a / b".
inline std::vector<std::string> overlappingHeaderWords(const std::string& pdf) {
  const std::string html = run("pdftotext -bbox '" + pdf + "' - 2>/dev/null");
  struct Word {
    double x0, y0, x1, y1;
    std::string text;
  };
  std::vector<std::string> out;
  std::vector<Word> words;
  int page = 0;
  const std::regex word_re(R"re(<word xMin="([0-9.]+)" yMin="([0-9.]+)" xMax="([0-9.]+)" yMax="([0-9.]+)">([^<]*)</word>)re");
  auto flush = [&] {
    for (size_t i = 0; i < words.size(); ++i)
      for (size_t j = i + 1; j < words.size(); ++j) {
        const Word &a = words[i], &b = words[j];
        if (a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1)
          out.push_back(std::to_string(page) + ": " + a.text + " / " + b.text);
      }
    words.clear();
  };
  std::istringstream in(html);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (line.find("<page ") != std::string::npos) {
      flush();
      ++page;
    }
    if (std::regex_search(line, m, word_re) && std::stod(m[4]) <= 34)
      words.push_back({std::stod(m[1]), std::stod(m[2]), std::stod(m[3]), std::stod(m[4]), m[5]});
  }
  flush();
  return out;
}

inline int pdfPages(const std::string& pdf) {
  std::istringstream info(run("pdfinfo '" + pdf + "' 2>/dev/null"));
  std::string line;
  while (std::getline(info, line))
    if (line.rfind("Pages:", 0) == 0) return std::stoi(line.substr(6));
  return -1;
}

struct Raster {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

// Page `page` rasterised at `dpi` (pdftoppm writes binary PPM).
inline Raster pageRaster(const std::string& pdf, int page, int dpi) {
  const std::string prefix = pdf + ".page";
  run("pdftoppm -r " + std::to_string(dpi) + " -f " + std::to_string(page) + " -l " + std::to_string(page) +
      " -singlefile '" + pdf + "' '" + prefix + "'");
  std::ifstream in(prefix + ".ppm", std::ios::binary);
  Raster r;
  std::string magic;
  int maxval = 0;
  in >> magic >> r.width >> r.height >> maxval;
  in.get();
  if (magic != "P6" || maxval != 255) return {};
  r.rgb.resize(size_t(r.width) * r.height * 3);
  in.read(reinterpret_cast<char*>(r.rgb.data()), static_cast<std::streamsize>(r.rgb.size()));
  return r;
}

struct Colours {
  size_t pixels = 0, ink = 0, blue = 0, red = 0;
};

// Pixels in the page rectangle (points from the top-left) that are not white,
// design blue (blue channel well above red and green) or flying red.
inline Colours countColours(const Raster& r, int dpi, float x, float y, float w, float h) {
  Colours c;
  const double s = dpi / 72.0;
  for (int py = int(y * s); py < int((y + h) * s) && py < r.height; ++py)
    for (int px = int(x * s); px < int((x + w) * s) && px < r.width; ++px) {
      const unsigned char* p = &r.rgb[(size_t(py) * r.width + px) * 3];
      ++c.pixels;
      if (p[0] < 235 || p[1] < 235 || p[2] < 235) ++c.ink;
      if (p[2] > 120 && p[2] > p[0] + 60 && p[2] > p[1] + 40) ++c.blue;
      if (p[0] > 90 && p[0] > p[1] + 50 && p[0] > p[2] + 50) ++c.red;
    }
  return c;
}

inline std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

}  // namespace sailshape::report_test

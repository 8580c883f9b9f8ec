#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <cstring>
#include <functional>
#include <random>

#include "analysis/core/errors.hpp"
#include "database/cloud_blob.hpp"
#include "database/import.hpp"
#include "database/schema.hpp"
#include "db_fixture.hpp"

namespace sailshape {
namespace {

using test::analysisDoc;
using test::TempDir;

int64_t count(Database& db, const std::string& sql) {
  Statement s = db.prepare(sql);
  s.step();
  return s.columnInt(0);
}

Cloud noisyCloud(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.004);
  Cloud c;
  for (size_t i = 0; i < n; ++i) {
    const double u = double(i % 200) / 200, v = double(i / 200) / (n / 200 + 1);
    c.points.emplace_back(3 * u, 0.3 * u * (1 - u) + noise(rng), 8 * v);
    c.intensity.push_back(float(i % 97));
  }
  return c;
}

ImportMetadata meta(int step, double awa) {
  ImportMetadata m;
  m.campaign = "Lorient 2025";
  m.boat = "Alpha";
  m.sail = "Gen-A";
  m.sail_type = "genoa";
  m.test = "sheet sweep";
  m.trim_step = step;
  m.awa_deg = awa;
  m.aws_m_s = 8.0;
  m.drive_n = 100.0 + step;
  m.side_n = 50.0;
  m.controls = {{"sheet", 0.1 * step}, {"tack_height", 0.5}};
  m.pressures_pa = {{"tap01", -120.0}};
  m.scanner_unit = "LMS511-1";
  m.scanned_at = "2025-06-01T10:00:00Z";
  m.settings = {{"frequency_hz", 25}};
  return m;
}

TEST(CloudBlob, RoundTripsPointsAndIntensity) {
  const Cloud c = noisyCloud(5000, 1);
  const std::vector<uint8_t> blob = compressCloud(c);
  EXPECT_LT(blob.size(), c.size() * 16);
  const Cloud d = decompressCloud(blob);
  ASSERT_EQ(d.size(), c.size());
  ASSERT_EQ(d.intensity.size(), c.size());
  for (size_t i = 0; i < c.size(); i += 37) {
    EXPECT_NEAR((d.points[i] - c.points[i]).norm(), 0.0, 1e-5);  // float32 at ≤ 10 m
    EXPECT_EQ(d.intensity[i], c.intensity[i]);
  }
  EXPECT_THROW(decompressCloud({1, 2, 3}), DatabaseError);
  std::vector<uint8_t> bad = blob;
  bad.resize(bad.size() / 2);
  EXPECT_THROW(decompressCloud(bad), DatabaseError);
}

// A blob as compressCloud lays it out, written here byte by byte: the uncompressed
// size, then zlib over "SSC1", the point count, `flags` and `body`.
std::vector<uint8_t> handMadeBlob(uint64_t n, uint32_t flags, const std::vector<float>& body) {
  std::vector<uint8_t> raw(16 + 4 * body.size());
  std::memcpy(raw.data(), "SSC1", 4);
  std::memcpy(raw.data() + 4, &n, 8);
  std::memcpy(raw.data() + 12, &flags, 4);
  std::memcpy(raw.data() + 16, body.data(), 4 * body.size());
  uLongf len = compressBound(raw.size());
  std::vector<uint8_t> blob(8 + len);
  const uint64_t size = raw.size();
  std::memcpy(blob.data(), &size, 8);
  EXPECT_EQ(compress2(blob.data() + 8, &len, raw.data(), raw.size(), 6), Z_OK);
  blob.resize(8 + len);
  return blob;
}

TEST(CloudBlob, KeepsTheScanAnglesAndTheViewpoint) {
  // A re-analysis of a stored scan needs both: the angles for the surface's
  // (α, β) triangulation, the viewpoint for the normals and the beam's footprint.
  Cloud c = noisyCloud(3000, 4);
  for (size_t i = 0; i < c.size(); ++i) {
    c.alpha_rad.push_back(-0.8 + 1e-3 * double(i % 200) + 1e-9 * double(i));
    c.beta_rad.push_back(2.5 + 1e-3 * double(i / 200));
  }
  c.viewpoint = Vec3(-8.123456789, -9.5, 5.25);
  const Cloud d = decompressCloud(compressCloud(c));
  ASSERT_EQ(d.alpha_rad.size(), c.size());
  ASSERT_EQ(d.beta_rad.size(), c.size());
  for (size_t i = 0; i < c.size(); ++i) {
    // float32 below 4: half an ulp, 1.2e-7 rad (4 µm across at 30 m).
    ASSERT_NEAR(d.alpha_rad[i], c.alpha_rad[i], 1.2e-7) << i;
    ASSERT_NEAR(d.beta_rad[i], c.beta_rad[i], 1.2e-7) << i;
  }
  ASSERT_TRUE(d.viewpoint.has_value());
  EXPECT_EQ(*d.viewpoint, *c.viewpoint);
  EXPECT_EQ(d.intensity, c.intensity);

  // Each attribute alone, and none.
  Cloud v;
  v.points = {Vec3(1, 2, 3), Vec3(4, 5, 6)};
  v.viewpoint = Vec3(0.5, 0, 0);
  Cloud w = decompressCloud(compressCloud(v));
  EXPECT_FALSE(w.hasIntensity());
  EXPECT_FALSE(w.hasScanAngles());
  ASSERT_TRUE(w.viewpoint.has_value());
  EXPECT_EQ(*w.viewpoint, Vec3(0.5, 0, 0));
  v.viewpoint.reset();
  w = decompressCloud(compressCloud(v));
  EXPECT_FALSE(w.viewpoint.has_value());
  EXPECT_EQ(w.points[1], Vec3(4, 5, 6));
}

TEST(CloudBlob, ReadsBlobsWrittenBeforeTheAnglesWereKept) {
  // Two points with intensity (flags 1): xyz xyz, then the two intensities.
  const Cloud d = decompressCloud(handMadeBlob(2, 1, {1, 2, 3, 4, 5, 6, 70, 80}));
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.points[1], Vec3(4, 5, 6));
  EXPECT_EQ(d.intensity, (std::vector<float>{70, 80}));
  EXPECT_FALSE(d.hasScanAngles());
  EXPECT_FALSE(d.viewpoint.has_value());
}

TEST(CloudBlob, RefusesFlagsItDoesNotKnow) {
  try {
    decompressCloud(handMadeBlob(1, 1 | 16, {1, 2, 3, 70, 0}));
    FAIL() << "a blob with flag 16 was read";
  } catch (const DatabaseError& e) {
    EXPECT_STREQ(e.what(), "[decompressCloud] cloud flags 0x11 are unknown: written by a newer sailshape");
  }
  // Angles announced but missing: the sizes do not add up.
  try {
    decompressCloud(handMadeBlob(2, 2, {1, 2, 3, 4, 5, 6}));
    FAIL() << "a blob short of its angles was read";
  } catch (const DatabaseError& e) {
    EXPECT_STREQ(e.what(), "[decompressCloud] 2 points do not fit 40 bytes");
  }
  // Lost lines announced: a count of none, and a count far beyond the bytes.
  EXPECT_TRUE(decompressCloud(handMadeBlob(1, 8, {1, 2, 3, 0})).lost_beta_rad.empty());  // a count of 0
  try {
    decompressCloud(handMadeBlob(1, 8, {1, 2, 3, 1.0f}));  // 1.0f read as a count of 1,065,353,216 lines
    FAIL() << "a blob short of its lost lines was read";
  } catch (const DatabaseError& e) {
    EXPECT_STREQ(e.what(), "[decompressCloud] 1 points do not fit 32 bytes");
  }
}

// A stored scan keeps the lines its sweep lost: a re-analysis widens the corners beside them.
TEST(CloudBlob, KeepsTheLinesTheSweepLost) {
  Cloud c = noisyCloud(100, 5);
  c.viewpoint = Vec3(1, 2, 3);
  c.lost_beta_rad = {-0.25, -0.1234567890123, 0.5};
  const Cloud d = decompressCloud(compressCloud(c));
  EXPECT_EQ(d.lost_beta_rad, c.lost_beta_rad);
  ASSERT_TRUE(d.viewpoint.has_value());
  EXPECT_EQ(*d.viewpoint, *c.viewpoint);
  c.lost_beta_rad.clear();
  EXPECT_TRUE(decompressCloud(compressCloud(c)).lost_beta_rad.empty());
}

TEST(Import, StoresAnalysisTrimStepAndCloudInOneTransaction) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  const nlohmann::json doc = analysisDoc(8.0);
  const Cloud cloud = noisyCloud(2000, 2);
  const ImportResult r = importScan(db, meta(1, 90.0), &doc, &cloud);
  EXPECT_EQ(r.sections, 3u);
  EXPECT_GT(r.analysis_id, 0);

  Statement s = db.prepare("SELECT point_count, cloud, settings, unit_id IS NOT NULL FROM scans WHERE id = ?");
  s.bind(1, r.scan_id);
  ASSERT_TRUE(s.step());
  EXPECT_EQ(s.columnInt(0), 2000);
  EXPECT_EQ(decompressCloud(s.columnBlob(1)).size(), 2000u);
  EXPECT_EQ(nlohmann::json::parse(s.columnText(2))["frequency_hz"], 25);
  EXPECT_EQ(s.columnInt(3), 1);

  Statement x = db.prepare("SELECT fraction, camber_pct, u_camber_pct, exit_deg, curve FROM sections WHERE analysis_id = ? ORDER BY fraction");
  x.bind(1, r.analysis_id);
  ASSERT_TRUE(x.step());
  EXPECT_DOUBLE_EQ(x.columnDouble(0), 0.25);
  EXPECT_DOUBLE_EQ(x.columnDouble(1), 8.0);
  EXPECT_DOUBLE_EQ(x.columnDouble(2), 0.2);
  EXPECT_TRUE(x.isNull(3));  // null in the JSON: not measurable
  const auto curve = unpackCurve(x.columnBlob(4));
  ASSERT_EQ(curve.size(), 3u);
  EXPECT_DOUBLE_EQ(curve[1].x(), 1.0);
  EXPECT_DOUBLE_EQ(curve[1].z(), 0.25);

  EXPECT_EQ(count(db, "SELECT count(*) FROM control_settings"), 2);
  EXPECT_EQ(count(db, "SELECT count(*) FROM pressures"), 1);
  Statement a = db.prepare("SELECT diagnostics, software_version FROM analyses");
  ASSERT_TRUE(a.step());
  EXPECT_EQ(nlohmann::json::parse(a.columnText(0))["points_in"], 50000);
  EXPECT_EQ(a.columnText(1), "0.1.0");

  // A second scan of the same trim step reuses it (and its campaign, sail, ...).
  const ImportResult r2 = importScan(db, meta(1, 90.0), &doc);
  EXPECT_EQ(r2.trim_step_id, r.trim_step_id);
  EXPECT_EQ(count(db, "SELECT count(*) FROM trim_steps"), 1);
  EXPECT_EQ(count(db, "SELECT count(*) FROM campaigns"), 1);
  EXPECT_EQ(count(db, "SELECT count(*) FROM scans"), 2);
  EXPECT_EQ(count(db, "SELECT point_count FROM scans WHERE id = " + std::to_string(r2.scan_id)), 50000);
}

TEST(Import, BadInputThrowsAndStoresNothing) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  const nlohmann::json doc = analysisDoc(8.0);
  const nlohmann::json not_analysis = {{"points", 3}};
  EXPECT_THROW(importScan(db, meta(0, 90), &not_analysis), InvalidInput);
  EXPECT_THROW(importScan(db, meta(0, 90), nullptr, nullptr), InvalidInput);
  ImportMetadata m = meta(0, 90);
  m.campaign_kind = "lake";
  EXPECT_THROW(importScan(db, m, &doc), InvalidInput);
  m = meta(0, 400);
  EXPECT_THROW(importScan(db, m, &doc), InvalidInput);
  m = meta(0, 90);
  m.sail.clear();
  EXPECT_THROW(importScan(db, m, &doc), InvalidInput);
  // A bad section is found after the trim step and scan rows were written: the
  // transaction rolls all of them back.
  nlohmann::json bad = analysisDoc(8.0);
  bad["sections"][2]["fraction"] = 1.5;
  EXPECT_THROW(importScan(db, meta(0, 90), &bad), InvalidInput);
  // So is an unmeasured section without a fraction in (0, 1) or a reason.
  for (const nlohmann::json& u : {nlohmann::json{{"fraction", 1.5}, {"reason", "x"}}, nlohmann::json{{"fraction", 0.5}},
                                  nlohmann::json("0.5")}) {
    nlohmann::json odd = analysisDoc(8.0);
    odd["unmeasured_sections"] = nlohmann::json::array({u});
    try {
      importScan(db, meta(0, 90), &odd);
      ADD_FAILURE() << u.dump();
    } catch (const InvalidInput& e) {
      EXPECT_NE(std::string(e.what()).find("unmeasured section needs a fraction in (0, 1) and a reason"), std::string::npos)
          << e.what();
    }
  }
  nlohmann::json odd = analysisDoc(8.0);
  odd["unmeasured_sections"] = {{{"fraction", 0.5}, {"reason", "x"}}};
  odd["diagnostics"] = "none";
  EXPECT_THROW(importScan(db, meta(0, 90), &odd), InvalidInput);
  odd["diagnostics"] = nlohmann::json::object();
  odd["unmeasured_sections"] = "0.5";
  EXPECT_THROW(importScan(db, meta(0, 90), &odd), InvalidInput);
  odd["unmeasured_sections"] = {{{"fraction", 0.5}, {"reason", "x"}}};  // analysisDoc measured 0.5
  try {
    importScan(db, meta(0, 90), &odd);
    ADD_FAILURE() << "0.5 both measured and not";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("is both measured and unmeasured"), std::string::npos) << e.what();
  }
  EXPECT_EQ(count(db, "SELECT count(*) FROM scans"), 0);
  EXPECT_EQ(count(db, "SELECT count(*) FROM trim_steps"), 0);
  EXPECT_EQ(count(db, "SELECT count(*) FROM campaigns"), 0);
}

TEST(Import, WrongTypedValuesAreRefusedNamingFieldAndSectionWhileNullIsNotMeasured) {
  TempDir dir;
  Database db = openSailDatabase(dir.file("a.db"));
  struct Case {
    std::function<void(nlohmann::json&)> spoil;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](nlohmann::json& d) { d["sections"][1]["camber_pct"] = "lots"; },
       "[importScan] section 0.500: camber_pct must be a number or null (got \"lots\")"},
      {[](nlohmann::json& d) { d["sections"][0]["plane_tilt_deg"] = true; },
       "[importScan] section 0.250: plane_tilt_deg must be a number or null (got true)"},
      {[](nlohmann::json& d) { d["sections"][2]["uncertainty"]["twist_deg"] = "0.5"; },
       "[importScan] section 0.750 uncertainty: twist_deg must be a number or null (got \"0.5\")"},
      {[](nlohmann::json& d) { d["sections"][2]["uncertainty"] = 0.5; },
       "[importScan] section 0.750: uncertainty must be an object (got 0.5)"},
      {[](nlohmann::json& d) { d["sections"][1]["converged"] = "yes"; },
       "[importScan] section 0.500: converged must be true or false (got \"yes\")"},
  };
  for (const Case& c : cases) {
    nlohmann::json doc = analysisDoc(8.0);
    c.spoil(doc);
    try {
      importScan(db, meta(0, 90), &doc);
      ADD_FAILURE() << c.message;
    } catch (const InvalidInput& e) {
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
  EXPECT_EQ(count(db, "SELECT count(*) FROM scans"), 0);
  EXPECT_EQ(count(db, "SELECT count(*) FROM sections"), 0);

  nlohmann::json doc = analysisDoc(8.0);
  doc["sections"][1]["camber_pct"] = nullptr;
  doc["sections"][1].erase("draft_pct");
  EXPECT_EQ(importScan(db, meta(0, 90), &doc).sections, 3u);
  EXPECT_EQ(count(db, "SELECT count(*) FROM sections WHERE camber_pct IS NULL AND draft_pct IS NULL AND fraction = 0.5"), 1);
}

TEST(Import, WriterKilledMidImportLeavesFileConsistentAndScanAbsent) {
  TempDir dir;
  const std::string path = dir.file("a.db");
  const nlohmann::json doc = analysisDoc(8.0);
  int64_t first_scan = 0;
  {
    Database db = openSailDatabase(path);
    first_scan = importScan(db, meta(0, 90.0), &doc).scan_id;
  }  // closed before fork: a connection must not cross it

  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    close(ready[0]);
    try {
      Database db = openSailDatabase(path);
      db.exec("PRAGMA cache_size=-64");  // 64 KiB: uncommitted pages spill into the WAL file
      const Cloud cloud = noisyCloud(200000, 3);
      importScan(db, meta(1, 95.0), &doc, &cloud, [&](const std::string& stage) {
        if (stage != "sections") return;
        const char c = 'k';
        if (write(ready[1], &c, 1) != 1) _exit(3);
        for (;;) pause();  // every row written, nothing committed: wait for SIGKILL
      });
    } catch (...) {
      _exit(2);
    }
    _exit(1);  // not reached when killed
  }
  close(ready[1]);
  char c = 0;
  ASSERT_EQ(read(ready[0], &c, 1), 1) << "child did not reach the middle of its import";
  close(ready[0]);
  // The half-written scan is on disk, not only in the child's memory.
  EXPECT_GT(std::filesystem::file_size(path + "-wal"), 500000u);
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGKILL);

  Database db = openSailDatabase(path);
  EXPECT_TRUE(db.integrityCheck().empty());
  EXPECT_EQ(count(db, "SELECT count(*) FROM scans"), 1);
  EXPECT_EQ(count(db, "SELECT id FROM scans"), first_scan);
  EXPECT_EQ(count(db, "SELECT count(*) FROM trim_steps"), 1);
  EXPECT_EQ(count(db, "SELECT count(*) FROM sections"), 3);
  EXPECT_EQ(count(db, "SELECT count(*) FROM scans WHERE point_count = 200000"), 0);
  // And the file takes new writes.
  importScan(db, meta(1, 95.0), &doc);
  EXPECT_EQ(count(db, "SELECT count(*) FROM scans"), 2);
}

TEST(Import, BlockedWriterFailsWithClearMessage) {
  TempDir dir;
  const std::string path = dir.file("a.db");
  Database holder = openSailDatabase(path);
  Transaction held(holder);
  OpenOptions o;
  o.busy_timeout_ms = 200;
  Database other = openSailDatabase(path, o);
  const nlohmann::json doc = analysisDoc(8.0);
  EXPECT_THROW(importScan(other, meta(0, 90), &doc), DatabaseBusy);
}

}  // namespace
}  // namespace sailshape

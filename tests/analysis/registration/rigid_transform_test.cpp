// Kabsch/SVD from point pairs, the aligning rotation, and the 4×4 transform file.
#include "analysis/registration/rigid_transform.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "analysis/core/units.hpp"
#include "tests/support/fixtures.hpp"

namespace sailshape {
namespace {

namespace fs = std::filesystem;

RigidTransform studyTransform() {
  // The study's check (§5.3.3): 90° about X, 1 m along each axis.
  RigidTransform t = RigidTransform::Identity();
  t.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  t.translation() = Vec3(1, 1, 1);
  return t;
}

std::vector<PointPair> pairsUnder(const RigidTransform& t, size_t n, double noise_m, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-3, 3);
  std::normal_distribution<double> N(0, 1);
  std::vector<PointPair> pairs;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 m(U(rng), U(rng), U(rng));
    pairs.push_back({m, t * m + noise_m * Vec3(N(rng), N(rng), N(rng))});
  }
  return pairs;
}

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sailshape_rigid_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  fs::path dir_;
};

TEST(Kabsch, RecoversTheStudyTransformFromExactPairs) {
  const RigidTransform truth = studyTransform();
  const KabschFit fit = fitKabsch(pairsUnder(truth, 4, 0, 1));
  EXPECT_LT(rotationDifferenceDeg(fit.transform.linear(), truth.linear()), 1e-9);
  EXPECT_LT((fit.transform.translation() - truth.translation()).norm(), 1e-12 * 1e3);
  EXPECT_LT(fit.rms_m, 1e-12);
  EXPECT_FALSE(fit.reflection_corrected);
}

TEST(Kabsch, NoisyPairsGiveErrorsOfTheNoiseOverTheSpread) {
  // 4 mm per coordinate on 200 pairs spread over ±3 m: the rotation is good to
  // about σ / (spread · √n) ≈ 0.004 / (1.7 · 14) rad ≈ 0.01°; allow 5×.
  const RigidTransform truth = studyTransform();
  const KabschFit fit = fitKabsch(pairsUnder(truth, 200, kSigma, 2));
  EXPECT_LT(rotationDifferenceDeg(fit.transform.linear(), truth.linear()), 0.05);
  EXPECT_LT((fit.transform.translation() - truth.translation()).norm(), 5 * kSigma * std::sqrt(3.0 / 200.0));
  EXPECT_NEAR(fit.rms_m, std::sqrt(3.0) * kSigma, 0.2 * std::sqrt(3.0) * kSigma);
}

TEST(Kabsch, AMirroredPointSetGivesARotationNotAReflection) {
  // Reference = moving mirrored in the XY plane: the best orthogonal map is a
  // reflection; the guard must return a proper rotation (det +1) and say so.
  std::vector<PointPair> pairs = pairsUnder(RigidTransform::Identity(), 20, 0, 3);
  for (PointPair& p : pairs) p.reference.z() = -p.reference.z();
  const KabschFit fit = fitKabsch(pairs);
  EXPECT_NEAR(fit.transform.linear().determinant(), 1.0, 1e-12);
  EXPECT_TRUE(fit.reflection_corrected);
  EXPECT_GT(fit.rms_m, 0.1);  // a rotation cannot fit a mirror image
}

TEST(Kabsch, PlanarPointsStillFixTheRotation) {
  // Three non-collinear points (a plane) are enough; the reflection guard must
  // not flip the rotation when the smallest singular value is zero.
  const RigidTransform truth = studyTransform();
  std::vector<PointPair> pairs;
  for (const Vec3& m : {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1.5, 0)}) pairs.push_back({m, truth * m});
  const KabschFit fit = fitKabsch(pairs);
  EXPECT_LT(rotationDifferenceDeg(fit.transform.linear(), truth.linear()), 1e-9);
  EXPECT_LT((fit.transform.translation() - truth.translation()).norm(), 1e-9);
}

TEST(Kabsch, BadPairsAreRejected) {
  expectInvalidInput([] { fitKabsch(pairsUnder(RigidTransform::Identity(), 2, 0, 1)); }, {"fitKabsch", "3", "got 2"});
  std::vector<PointPair> line;
  for (int i = 0; i < 5; ++i) line.push_back({Vec3(i, 2.0 * i, 0), Vec3(i, 2.0 * i, 1)});
  expectInvalidInput([&] { fitKabsch(line); }, {"fitKabsch", "collinear"});
  std::vector<PointPair> nan = pairsUnder(RigidTransform::Identity(), 4, 0, 1);
  nan[2].moving.x() = std::nan("");
  expectInvalidInput([&] { fitKabsch(nan); }, {"fitKabsch", "pair 2", "non-finite"});
}

TEST(RotationAligning, TakesOneDirectionOntoAnother) {
  const Vec3 from = Vec3(1, 2, -0.5).normalized(), to = Vec3(-0.3, 0.1, 1).normalized();
  const Eigen::Matrix3d r = rotationAligning(from, to);
  EXPECT_LT((r * from - to).norm(), 1e-12);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  // The shortest rotation: its axis is normal to both.
  EXPECT_LT((r * from.cross(to).normalized() - from.cross(to).normalized()).norm(), 1e-12);
  // Antiparallel and identical directions.
  const Eigen::Matrix3d flip = rotationAligning(Vec3::UnitZ(), -Vec3::UnitZ());
  EXPECT_LT((flip * Vec3::UnitZ() + Vec3::UnitZ()).norm(), 1e-12);
  EXPECT_NEAR(flip.determinant(), 1.0, 1e-12);
  EXPECT_LT((rotationAligning(from, from) - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  expectInvalidInput([] { rotationAligning(Vec3::Zero(), Vec3::UnitX()); }, {"rotationAligning", "non-zero"});
}

TEST(RotationDifference, MeasuresTheAngleBetweenRotations) {
  const Eigen::Matrix3d a = Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d b = Eigen::AngleAxisd(1e-7, Vec3(1, 1, 0).normalized()).toRotationMatrix() * a;
  EXPECT_NEAR(rotationDifferenceDeg(a, b), 1e-7 * kDegPerRad, 1e-12);  // small angles stay exact
  EXPECT_NEAR(rotationDifferenceDeg(Eigen::Matrix3d::Identity(), a), 0.3 * kDegPerRad, 1e-9);
}

TEST(TransformCloud, MovesPointsAndViewpoint) {
  Cloud c;
  c.points = {Vec3(1, 0, 0), Vec3(0, 2, 0)};
  c.intensity = {1.f, 2.f};
  c.viewpoint = Vec3(0, 0, 0);
  const Cloud out = transformCloud(c, studyTransform());
  EXPECT_LT((out.points[1] - Vec3(1, 1, 3)).norm(), 1e-12);  // (0,2,0) → (0,0,2) + (1,1,1)
  EXPECT_LT((*out.viewpoint - Vec3(1, 1, 1)).norm(), 1e-12);
  EXPECT_EQ(out.intensity, c.intensity);
}

TEST_F(TempDir, ATransformFileRoundTripsExactly) {
  RigidTransform t = RigidTransform::Identity();
  t.linear() = Eigen::AngleAxisd(0.7, Vec3(0.2, -1, 0.4).normalized()).toRotationMatrix();
  t.translation() = Vec3(1.234567891234, -0.5, 12.0);
  const std::string path = (dir_ / "t.txt").string();
  writeTransform(path, t);
  // Four lines of four numbers, the last 0 0 0 1.
  std::ifstream in(path);
  std::string line;
  int rows = 0;
  std::string last;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    double v;
    int count = 0;
    while (ss >> v) ++count;
    EXPECT_EQ(count, 4) << line;
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, 4);
  EXPECT_EQ(last, "0 0 0 1");
  const RigidTransform back = readTransform(path);
  EXPECT_LT((back.matrix() - t.matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST_F(TempDir, ReadsATransformWithCommentsAndCommas) {
  const std::string path = write("t.txt", "# from the tunnel session\n1 0 0 1\n0, 0, -1, 1\n\n0 1 0 1  # row 3\n0 0 0 1\n");
  const RigidTransform t = readTransform(path);
  EXPECT_LT(rotationDifferenceDeg(t.linear(), studyTransform().linear()), 1e-9);
  EXPECT_LT((t.translation() - Vec3(1, 1, 1)).norm(), 1e-15);
}

TEST_F(TempDir, BadTransformFilesNameTheFileAndLine) {
  const std::string missing = (dir_ / "none.txt").string();
  expectFileError([&] { readTransform(missing); }, missing, {});
  const std::string three = write("three.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  expectFileError([&] { readTransform(three); }, three, {"4 rows", "found 3"});
  const std::string five = write("five.txt", "1 0 0 0\n0 1 0 0 7\n0 0 1 0\n0 0 0 1\n");
  expectFileError([&] { readTransform(five); }, five, {"line 2", "expected 4 numbers, found 5"});
  const std::string last = write("last.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1\n");
  expectFileError([&] { readTransform(last); }, last, {"line 4", "0 0 0 1"});
  const std::string scaled = write("scaled.txt", "2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  expectFileError([&] { readTransform(scaled); }, scaled, {"not a rotation"});
  const std::string mirror = write("mirror.txt", "1 0 0 0\n0 1 0 0\n0 0 -1 0\n0 0 0 1\n");
  expectFileError([&] { readTransform(mirror); }, mirror, {"not a rotation", "det"});
  const std::string text = write("text.txt", "1 0 0 0\n0 one 0 0\n0 0 1 0\n0 0 0 1\n");
  expectFileError([&] { readTransform(text); }, text, {"line 2", "one"});
  const std::string inf = write("inf.txt", "1 0 0 inf\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  expectFileError([&] { readTransform(inf); }, inf, {"line 1", "non-finite"});
  RigidTransform bad = RigidTransform::Identity();
  bad.translation().x() = std::nan("");
  expectInvalidInput([&] { writeTransform((dir_ / "nan.txt").string(), bad); }, {"writeTransform", "non-finite"});
  expectFileError([&] { writeTransform((dir_ / "no_dir" / "t.txt").string(), RigidTransform::Identity()); },
                  (dir_ / "no_dir" / "t.txt").string(), {});
}

TEST_F(TempDir, ReadsPointPairsAndRejectsBadLines) {
  const std::string good = write("pairs.txt", "# moving  reference\n0 0 0  1 1 1\n1 0 0 2 1 1\n\n0 1 0 1 1 2\n");
  const auto pairs = readPointPairs(good);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[2].moving, Vec3(0, 1, 0));
  EXPECT_EQ(pairs[2].reference, Vec3(1, 1, 2));
  const std::string five = write("five.txt", "0 0 0 1 1 1\n0 0 0 1 1\n");
  expectFileError([&] { readPointPairs(five); }, five, {"line 2", "expected 6 numbers", "found 5"});
  const std::string empty = write("empty.txt", "# nothing\n\n");
  expectFileError([&] { readPointPairs(empty); }, empty, {"no point pairs"});
  const std::string missing = (dir_ / "none.txt").string();
  expectFileError([&] { readPointPairs(missing); }, missing, {});
}

}  // namespace
}  // namespace sailshape

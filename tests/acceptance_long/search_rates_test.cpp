// SPDX-License-Identifier: Apache-2.0
// Table 4.4 of `hrcsense eval --study` end to end (docs/EVALUATION.md): each backend timed on
// the synthetic person at 10^2 … 10^6 points. Rates are measurements and are not checked
// against numbers; what must hold is that every backend found brute force's closest distance
// at every size (they are exact), that the distance is the cloud's true one at the small sizes
// (by a scan written here), and that every size and backend has a positive rate. Release builds
// only, under the ctest label `long`.

#include "../support/run_cli.hpp"
#include "hrcsense/sim/person_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

TEST(SearchRates, EveryBackendFindsTheTrueClosestDistanceAtEverySize) {
  const std::string dir = std::string(::testing::TempDir()) + "search_rates";
  std::filesystem::remove_all(dir);
  const test::CliResult r = test::cli("eval --study table-4.4 --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::ifstream in(dir + "/table-4.4/results.csv");
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(line, "backend,points,seconds_per_search,searches_per_s,distance_m");
  std::map<long, std::vector<double>> distances;  // per size, every backend's
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream split(line);
    for (std::string field; std::getline(split, field, ',');) f.push_back(field);
    ASSERT_EQ(f.size(), 5U) << line;
    EXPECT_GT(std::stod(f[3]), 0.0) << line;
    distances[std::stol(f[1])].push_back(std::stod(f[4]));
    ++rows;
  }
  EXPECT_EQ(rows, 15);  // brute, octree h=4, kdtree × 5 sizes
  const Eigen::Vector3f robot = person_cloud_robot_point().capsules[0].a;
  for (const auto& [n, found] : distances) {
    SCOPED_TRACE(n);
    ASSERT_EQ(found.size(), 3U);
    EXPECT_EQ(found[1], found[0]);
    EXPECT_EQ(found[2], found[0]);
    if (n <= 100'000) {
      const PointCloud cloud = person_cloud(static_cast<size_t>(n));
      double nearest = INFINITY;
      for (size_t i = 0; i < cloud.size(); ++i) nearest = std::min(nearest, double((cloud.point(i) - robot).norm()));
      EXPECT_NEAR(found[0], nearest, 1e-6);
    }
  }
  const std::string report = [&] {
    std::ifstream md(dir + "/THESIS-REPLICATION.md");
    std::stringstream s;
    s << md.rdbuf();
    return s.str();
  }();
  EXPECT_NE(report.find("## Table 4.4"), std::string::npos);
  EXPECT_NE(report.find("the same closest distance as brute force at every size"), std::string::npos) << report;
  EXPECT_TRUE(std::filesystem::exists(dir + "/table-4.4/search_rate.png"));
}

}  // namespace
}  // namespace hrcsense

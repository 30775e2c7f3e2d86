#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/placement_out.hpp"
#include "synthetic.hpp"

using namespace tt::placement;

TEST(PlacementOut, WritesJsonAndCsvThatReadBack) {
  const auto input = synthetic::c54_input(0.01, 5);
  PlacementOptions o;
  o.m_max = 3;
  o.saturation.shuffles = 99;
  o.saturation.sampled_combinations = 20;
  o.methods = {Method::kHistogramMi, Method::kGaussianGreedy, Method::kCorrelation};
  const auto result = place_all(input, o);

  const auto dir = std::filesystem::temp_directory_path() / "tt_placement_out_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  tt::io::write_placement_json(dir / "placement.json", result);
  tt::io::write_mi_ranking_csv(dir / "mi_ranking.csv", result);
  EXPECT_FALSE(std::filesystem::exists(dir / "placement.json.tmp"));

  std::ifstream jf(dir / "placement.json");
  const auto doc = nlohmann::json::parse(jf);
  EXPECT_EQ(doc["samples"], 100);
  EXPECT_EQ(doc["targets"]["dy"]["ksg_pool_size"], 0) << "KSG was not run";
  EXPECT_EQ(doc["mirror_twins_kept_dropped"].size(), 24u);
  const auto& hist = doc["targets"]["dy"]["methods"]["histogram_mi"];
  ASSERT_EQ(hist.size(), 3u);
  EXPECT_EQ(hist[0]["m"], 1);
  EXPECT_EQ(hist[2]["ids"].size(), 3u);
  EXPECT_TRUE(hist[2]["saturation"].contains("p_value"));
  EXPECT_TRUE(hist[2]["saturation"]["saturated"].is_boolean());
  EXPECT_TRUE(hist[2]["saturation"]["at_ceiling"].is_boolean());
  EXPECT_EQ(doc["targets"]["dz"]["methods"]["gaussian_greedy"][1]["ids"].size(), 2u);
  EXPECT_EQ(hist[0]["ids"][0].get<int>(),
            tt::core::index_of(result.targets[0].selections[0].ids[0]));

  std::ifstream cf(dir / "mi_ranking.csv");
  std::string header, line;
  std::getline(cf, header);
  EXPECT_EQ(header, "id,x_m,y_m,z_m,mi_bits_dy,rank_dy,mi_bits_dz,rank_dz");
  int rows = 0;
  std::getline(cf, line);
  ++rows;
  EXPECT_EQ(line.substr(0, 15), "1,-0.08,0.3,0.0");
  while (std::getline(cf, line)) ++rows;
  EXPECT_EQ(rows, 54);
  std::filesystem::remove_all(dir);
}

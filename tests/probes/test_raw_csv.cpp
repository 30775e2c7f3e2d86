#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/errors.hpp"
#include "probe_fixtures.hpp"
#include "probes/raw_csv.hpp"

using namespace tt::probes;

namespace {

const char* header =
    "# speed_rpm=6000 sample_rate_hz=1000 probe_distance_mm=150\n"
    "reading,time_s,sample,s1_um,s2_um,s3_um,s4_um\n";

/// A valid file of two readings of 15 samples (1.5 revolutions at 10 samples per revolution).
std::string valid_body() {
  std::ostringstream out;
  for (int r = 1; r <= 2; ++r)
    for (int j = 0; j < 15; ++j) out << r << "," << (r - 1) * 60 << "," << j << ",1.5,2,3,-4\n";
  return out.str();
}

std::filesystem::path written(const std::string& name, const std::string& text) {
  const auto path = fixtures::scratch_dir("raw_csv_" + name) / "raw.csv";
  std::ofstream(path) << text;
  return path;
}

/// what() of the DataError that reading `text` throws, or "" if it throws none.
std::string data_error(const std::string& name, const std::string& text,
                       const RawCsvConstants& given = {}) {
  try {
    read_raw_csv(written(name, text), given);
  } catch (const tt::core::DataError& e) {
    return e.what();
  }
  return "";
}

/// Replaces line `line` (1-based) of text.
std::string with_line(const std::string& text, int line, const std::string& replacement) {
  std::istringstream in(text);
  std::string out, l;
  for (int k = 1; std::getline(in, l); ++k) out += (k == line ? replacement : l) + "\n";
  return out;
}

}  // namespace

TEST(RawCsv, ReadsAValidFileInSI) {
  const ProbeRecord r = read_raw_csv(written("valid", header + valid_body()));
  ASSERT_EQ(r.readings.size(), 2u);
  EXPECT_DOUBLE_EQ(r.speed_rev_per_s, 100.0);
  EXPECT_DOUBLE_EQ(r.sample_rate_hz, 1000.0);
  EXPECT_DOUBLE_EQ(r.probe_distance_m, 0.15);
  EXPECT_DOUBLE_EQ(r.readings[1].start_time_s, 60.0);
  EXPECT_EQ(r.readings[1].samples_m.rows(), 15);
  EXPECT_DOUBLE_EQ(r.readings[1].samples_m(3, s1_y1), 1.5e-6);
  EXPECT_DOUBLE_EQ(r.readings[1].samples_m(3, s4_x2), -4e-6);
  EXPECT_FALSE(r.has_axial_probe());
}

TEST(RawCsv, RoundTripsAVirtualRecordWithAnAxialProbe) {
  VirtualProbeSetup s = fixtures::runout_setup(9);
  s.axial_probe = true;
  const VirtualRecord v = virtual_record(s, fixtures::warm_up_history(3));
  const auto path = fixtures::scratch_dir("raw_csv_roundtrip") / "raw.csv";
  write_text_atomically(path, raw_csv_text(v.record));
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
  const ProbeRecord back = read_raw_csv(path);
  ASSERT_EQ(back.readings.size(), 3u);
  EXPECT_TRUE(back.has_axial_probe());
  EXPECT_NEAR(back.speed_rev_per_s, v.record.speed_rev_per_s, 1e-12);
  EXPECT_NEAR(back.probe_distance_m, s.probe_distance_m, 1e-15);
  EXPECT_NEAR((back.readings[2].samples_m - v.record.readings[2].samples_m).cwiseAbs().maxCoeff(),
              0.0, 1e-12);
}

TEST(RawCsv, ConstantsMayComeFromOptionsButMustAgree) {
  const std::string no_header = "reading,time_s,sample,s1_um,s2_um,s3_um,s4_um\n" + valid_body();
  EXPECT_NE(data_error("missing", no_header).find("speed_rpm is missing"), std::string::npos);
  const ProbeRecord r = read_raw_csv(written("given", no_header), {6000.0, 1000.0, 100.0});
  EXPECT_DOUBLE_EQ(r.probe_distance_m, 0.1);
  const std::string clash = data_error("clash", header + valid_body(), {3000.0, {}, {}});
  EXPECT_NE(clash.find(":1: speed_rpm=6000 in the header but 3000"), std::string::npos) << clash;
}

TEST(RawCsv, MalformedRowsNameFileLineAndColumn) {
  const std::string text = header + valid_body();
  // Line 6 is reading 1, sample 3.
  std::string e = data_error("nan", with_line(text, 6, "1,0,3,1.5,abc,3,-4"));
  EXPECT_NE(e.find("raw.csv:6: column 5 (s2_um): 'abc' is not a displacement in µm"),
            std::string::npos)
      << e;
  e = data_error("short_row", with_line(text, 6, "1,0,3,1.5,2,3"));
  EXPECT_NE(e.find("raw.csv:6: column 7: 6 fields, expected 7"), std::string::npos) << e;
  e = data_error("gap", with_line(text, 6, "1,0,4,1.5,2,3,-4"));
  EXPECT_NE(e.find("raw.csv:6: column 3 (sample): '4' is not 3"), std::string::npos) << e;
  e = data_error("time", with_line(text, 6, "1,0.5,3,1.5,2,3,-4"));
  EXPECT_NE(e.find("raw.csv:6: column 2 (time_s)"), std::string::npos) << e;
  e = data_error("reading", with_line(text, 6, "x,0,3,1.5,2,3,-4"));
  EXPECT_NE(e.find("raw.csv:6: column 1 (reading)"), std::string::npos) << e;
  e = data_error("header", with_line(text, 2, "reading,time_s,sample,s1_um,s2_um,s3,s4_um"));
  EXPECT_NE(e.find("raw.csv:2: column 6: header 's3', expected 's3_um'"), std::string::npos) << e;
  e = data_error("bad_meta", with_line(text, 1, "# speed_rpm=fast"));
  EXPECT_NE(e.find("raw.csv:1: speed_rpm='fast'"), std::string::npos) << e;
}

TEST(RawCsv, RejectsAReadingShorterThanOneRevolution) {
  // Reading 2 ends after 8 samples: 0.8 revolutions at 10 samples per revolution.
  std::ostringstream body;
  for (int j = 0; j < 15; ++j) body << "1,0," << j << ",1,2,3,4\n";
  for (int j = 0; j < 8; ++j) body << "2,60," << j << ",1,2,3,4\n";
  const std::string e = data_error("short_reading", header + body.str());
  EXPECT_NE(e.find("raw.csv:25:"), std::string::npos) << e;
  EXPECT_NE(e.find("reading 2 ends after 8 samples = 0.8 revolutions"), std::string::npos) << e;
  EXPECT_NE(e.find("more than one revolution"), std::string::npos) << e;
}

TEST(RawCsv, DriftHistoryReadsBackADriftCsv) {
  DriftSeries d;
  d.points = {{0.0, {}, 0.0, 0.0}, {600.0, {1e-6, -2e-6, 3e-6, -4e-6, 0.0}, 1e-5, -1e-5}};
  const auto path = fixtures::scratch_dir("raw_csv_history") / "drift.csv";
  write_text_atomically(path, drift_csv_text(d));
  const DriftHistory h = read_drift_history_csv(path);
  ASSERT_EQ(h.size(), 2u);
  EXPECT_DOUBLE_EQ(h[1].time_s, 600.0);
  EXPECT_NEAR(h[1].drift.y2_m, -4e-6, 1e-15);
  EXPECT_THROW(read_drift_history_csv(written("no_x1", "time_s,y1_um\n0,1\n")),
               tt::core::DataError);
  EXPECT_THROW(read_raw_csv("/nonexistent/raw.csv"), tt::core::IoError);
}

// CSV tables: round trips, precision, and errors that name the file, line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "core/errors.hpp"
#include "io/csv_out.hpp"
#include "tiny_mesh.hpp"

namespace tt::io {
namespace {

namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Csv, RoundTripAtFullPrecisionIsExact) {
  const auto dir = test::scratch_dir("csv_exact");
  Eigen::MatrixXd rows(4, 3);
  rows << 0.0, 20.1, -1.0 / 3.0,                              //
      60.0, 1e-300, 6.02214076e23,                            //
      120.5, -0.0, std::numeric_limits<double>::quiet_NaN(),  //
      1e9, 123456789.123456789, std::numeric_limits<double>::infinity();
  write_csv(dir / "t.csv", {"time_s", "T02_degC", "dy_um"}, rows, 17);
  const CsvTable table = read_numeric_csv(dir / "t.csv");
  ASSERT_EQ(table.header, (std::vector<std::string>{"time_s", "T02_degC", "dy_um"}));
  ASSERT_EQ(table.rows.rows(), 4);
  ASSERT_EQ(table.rows.cols(), 3);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (std::isnan(rows(r, c))) {
        EXPECT_TRUE(std::isnan(table.rows(r, c)));
      } else {
        EXPECT_EQ(table.rows(r, c), rows(r, c)) << r << "," << c;
      }
    }
  }
  EXPECT_EQ(table.column_index("dy_um"), 2);
  EXPECT_EQ(table.column("T02_degC")(0), 20.1);
  EXPECT_FALSE(fs::exists(dir / "t.csv.tmp"));
}

TEST(Csv, DefaultPrecisionKeepsTenSignificantDigits) {
  const auto dir = test::scratch_dir("csv_default");
  Eigen::MatrixXd rows(1, 2);
  rows << 1.0 / 3.0, 2.0 / 3.0 * 1e-7;
  write_csv(dir / "t.csv", {"a", "b"}, rows);
  EXPECT_EQ(read_text(dir / "t.csv"), "a,b\n0.3333333333,6.666666667e-08\n");
  const CsvTable table = read_numeric_csv(dir / "t.csv");
  EXPECT_NEAR(table.rows(0, 0), rows(0, 0), 1e-10);
  EXPECT_NEAR(table.rows(0, 1) / rows(0, 1), 1.0, 1e-9);
  EXPECT_GT(std::abs(table.rows(0, 0) - rows(0, 0)), 0.0);  // rounded, not exact
}

TEST(Csv, TextInANumberCellNamesLineAndColumn) {
  const auto dir = test::scratch_dir("csv_text");
  write_text(dir / "bad.csv", "time_s,T02_degC,T10_degC\n0,20,21\n60,20.5,abc\n");
  try {
    read_numeric_csv(dir / "bad.csv");
    FAIL() << "text in a number cell was accepted";
  } catch (const core::DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.csv:3:"), std::string::npos) << what;
    EXPECT_NE(what.find("column 3"), std::string::npos) << what;
    EXPECT_NE(what.find("T10_degC"), std::string::npos) << what;
    EXPECT_NE(what.find("abc"), std::string::npos) << what;
  }
  write_text(dir / "partial.csv", "a,b\n1,2.5x\n");
  EXPECT_THROW(read_numeric_csv(dir / "partial.csv"), core::DataError);
  write_text(dir / "empty_cell.csv", "a,b\n1,\n");
  EXPECT_THROW(read_numeric_csv(dir / "empty_cell.csv"), core::DataError);
}

TEST(Csv, RowWithWrongCellCountIsRejected) {
  const auto dir = test::scratch_dir("csv_count");
  write_text(dir / "short.csv", "a,b,c\n1,2,3\n\n4,5\n");
  try {
    read_numeric_csv(dir / "short.csv");
    FAIL() << "a short row was accepted";
  } catch (const core::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv:4:"), std::string::npos) << e.what();
  }
}

TEST(Csv, CommentsBlankLinesAndCrLfAreAccepted) {
  const auto dir = test::scratch_dir("csv_lenient");
  write_text(dir / "t.csv",
             "# measured run 3\r\n time_s , \"dz_um\"\r\n\r\n0, +1.5\r\n60,-2e1\r\n");
  const CsvTable table = read_numeric_csv(dir / "t.csv");
  ASSERT_EQ(table.header, (std::vector<std::string>{"time_s", "dz_um"}));
  ASSERT_EQ(table.rows.rows(), 2);
  EXPECT_EQ(table.rows(0, 1), 1.5);
  EXPECT_EQ(table.rows(1, 1), -20.0);
  // A spreadsheet's UTF-8 byte-order mark before the header is not part of the first name.
  write_text(dir / "bom.csv", "\xEF\xBB\xBFtime_s,dz_um\n0,1\n");
  EXPECT_EQ(read_numeric_csv(dir / "bom.csv").header,
            (std::vector<std::string>{"time_s", "dz_um"}));
}

TEST(Csv, BadInputsAreRejected) {
  const auto dir = test::scratch_dir("csv_bad");
  EXPECT_THROW(write_csv(dir / "t.csv", {"a"}, Eigen::MatrixXd::Zero(2, 2)), core::DataError);
  EXPECT_THROW(write_csv(dir / "t.csv", {"a,b", "c"}, Eigen::MatrixXd::Zero(2, 2)),
               core::DataError);
  EXPECT_THROW(write_csv(dir / "t.csv", {"a", "b"}, Eigen::MatrixXd::Zero(2, 2), 0),
               core::DataError);
  EXPECT_FALSE(fs::exists(dir / "t.csv"));
  EXPECT_THROW(read_numeric_csv(dir / "missing.csv"), core::IoError);
  write_text(dir / "dup.csv", "a,a\n1,2\n");
  EXPECT_THROW(read_numeric_csv(dir / "dup.csv"), core::DataError);
  write_text(dir / "blank.csv", "\n# nothing\n");
  EXPECT_THROW(read_numeric_csv(dir / "blank.csv"), core::DataError);
  write_text(dir / "ok.csv", "a,b\n");
  const CsvTable header_only = read_numeric_csv(dir / "ok.csv");
  EXPECT_EQ(header_only.rows.rows(), 0);
  EXPECT_EQ(header_only.rows.cols(), 2);
  EXPECT_THROW(header_only.column("c"), core::DataError);
}

}  // namespace
}  // namespace tt::io

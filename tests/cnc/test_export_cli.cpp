// thermotwin export end to end (child processes of build/thermotwin): a small fit.json exported in
// every format with its error figures, and bad input refused with exit 1, a message naming the
// file and key, and no output folder.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cnc_fixture.hpp"
#include "io/child_process.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string exe = TT_BINARY_DIR "/thermotwin";

struct ExportRun {
  int status = 0;
  std::string output;
};

ExportRun export_run(const fs::path& dir, std::vector<std::string> args) {
  const fs::path log = dir / "log.txt";
  fs::remove(log);
  args.insert(args.begin(), {exe, "export"});
  ExportRun r;
  r.status = tt::io::run_program(args, {}, log);
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  r.output = text.str();
  return r;
}

void write(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(ExportCli, WritesEveryFormatAndRefusesBadInput) {
  const fs::path dir = fs::temp_directory_path() / ("tt_export_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  write(dir / "fit.json", tt::test::fit_document().dump());
  write(dir / "states.csv", "time_s,a_degC,b_degC\n0,20,20\n60,21,20.5\n120,23,21.5\n");
  // A second run from its own reference: its 1 K on a counts from 30 °C.
  write(dir / "states2.csv", "time_s,b,a\n0,25,30\n60,25,31\n");

  const ExportRun ok =
      export_run(dir, {"--model", (dir / "fit.json").string(), "--out", (dir / "out").string(),
                       "--states", (dir / "states.csv").string(), "--states",
                       (dir / "states2.csv").string(), "--table-points", "41"});
  ASSERT_EQ(ok.status, 0) << ok.output;
  for (const char* f :
       {"sinumerik/THERMOTWIN_TEMP_COMP.SPF", "twincat/thermotwin_compensation.st",
        "twincat/thermotwin_tables.csv", "heidenhain/TT_B00.COM", "heidenhain/THERMOTWIN_9231.txt",
        "linuxcnc/thermotwin_eoffset.hal", "linuxcnc/thermotwin_eoffset.ini", "export.md"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  const json report = json::parse(std::ifstream(dir / "out" / "export.json"));
  ASSERT_EQ(report["states"].size(), 2u);
  EXPECT_EQ(report["states"][0]["samples"], 3);
  EXPECT_EQ(report["states"][1]["samples"], 2);
  // dx is p^3 per K of a: the line leaves 0.4 L^3 = 0.4 µm per K at the ends (L = 1 m); with
  // 3 K on a in the last state, 1.2 µm. The polynomial is exact to its count.
  const json& f = report["formats"];
  EXPECT_NEAR(f["sinumerik"]["error_on_states"]["dx"]["max_um"].get<double>(), 1.2, 1e-6);
  EXPECT_NEAR(f["sinumerik"]["error_per_unit"]["dx"]["max_um"].get<double>(), 0.4, 1e-6);
  EXPECT_LE(f["linuxcnc"]["error_on_states"]["dx"]["max_um"].get<double>(), 0.01 + 1e-9);
  EXPECT_LE(f["heidenhain"]["error_on_states"]["dz"]["max_um"].get<double>(), 0.05 + 1e-9);
  EXPECT_LT(f["twincat"]["error_on_states"]["dy"]["max_um"].get<double>(), 1e-9);

  // Refused: an axis model without coefficients, an unknown format, samples without a sensor.
  json bad = tt::test::fit_document();
  bad["axis"]["targets"]["A04_dz"].erase("coefficients");
  write(dir / "bad.json", bad.dump());
  const ExportRun r1 = export_run(
      dir, {"--model", (dir / "bad.json").string(), "--out", (dir / "bad_out").string()});
  EXPECT_EQ(r1.status, 1);
  EXPECT_NE(r1.output.find("bad.json: axis.targets.A04_dz.coefficients is missing"),
            std::string::npos)
      << r1.output;
  const ExportRun r2 = export_run(dir, {"--model", (dir / "fit.json").string(), "--out",
                                        (dir / "bad_out").string(), "--format", "fanuc"});
  EXPECT_EQ(r2.status, 1);
  EXPECT_NE(r2.output.find("'fanuc'"), std::string::npos) << r2.output;
  write(dir / "no_a.csv", "time_s,b\n0,20\n60,21\n");
  const ExportRun r3 =
      export_run(dir, {"--model", (dir / "fit.json").string(), "--out", (dir / "bad_out").string(),
                       "--states", (dir / "no_a.csv").string()});
  EXPECT_EQ(r3.status, 1);
  EXPECT_NE(r3.output.find("no_a.csv: column 'a' is missing"), std::string::npos) << r3.output;
  EXPECT_FALSE(fs::exists(dir / "bad_out"));
  EXPECT_FALSE(fs::exists(dir / "bad_out.partial"));
  fs::remove_all(dir);
}

}  // namespace

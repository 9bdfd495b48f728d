// CSV, summary and atomic file output.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/support/catch.h"
#include <nlohmann/json.hpp>

#include "common/csv.h"
#include "common/obj.h"
#include "common/output.h"
#include "common/summary.h"
#include "tests/support/scratch.h"

namespace {
std::string read(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("doubles are written so that they read back exactly", "[common][output]") {
  for (double value : {0.1, 1.0 / 3.0, -2.5e-300, 6.02214076e23}) {
    CAPTURE(value);
    CHECK(std::stod(cl::format_double(value)) == value);
  }
}

TEST_CASE("a CSV table is written whole into a new directory", "[common][output]") {
  const cl::test::ScratchDir scratch("output_csv");
  const std::filesystem::path dir = scratch.path();
  cl::CsvTable table({"a", "b", "c"});
  table.add_row({0.1, 2LL, std::string("x")});
  CHECK_THROWS_AS(table.add_row({1.0}), std::invalid_argument);
  table.write((dir / "sub" / "t.csv").string());
  CHECK(read(dir / "sub" / "t.csv") == "a,b,c\n0.10000000000000001,2,x\n");
  CHECK_FALSE(std::filesystem::exists(dir / "sub" / "t.csv.part"));
}

TEST_CASE("CSV text with commas, quotes or line breaks is quoted as RFC 4180 says", "[common][output]") {
  cl::CsvTable table({"why", "n"});
  table.add_row({std::string("plain"), 1LL});
  table.add_row({std::string("blew up at 0.5 s, strain 3"), 2LL});
  table.add_row({std::string("said \"stop\""), 3LL});
  table.add_row({std::string("two\nlines"), 4LL});
  CHECK(table.text() == "why,n\nplain,1\n\"blew up at 0.5 s, strain 3\",2\n\"said \"\"stop\"\"\",3\n\"two\nlines\",4\n");
}

TEST_CASE("the run summary has the contract's keys and exact positions", "[common][output]") {
  const cl::test::ScratchDir scratch("output_summary");
  const std::filesystem::path dir = scratch.path();
  cl::RunSummary summary;
  summary.lab = "lab01_single_spring";
  summary.method = "single-pass";
  summary.scene = "s";
  summary.positions = Eigen::Matrix3Xd::Constant(3, 2, 0.1);
  summary.positions(2, 1) = 1.0 / 3.0;
  summary.max_strain_error = 1e-17;
  summary.seconds = 0.5;
  summary.extra["rms_strain_error"] = 0.0;
  cl::write_summary((dir / "s.json").string(), summary);
  const nlohmann::json parsed = nlohmann::json::parse(read(dir / "s.json"));
  CHECK(parsed["lab"] == "lab01_single_spring");
  CHECK(parsed["positions"][1][2].get<double>() == 1.0 / 3.0);
  CHECK(parsed["max_strain_error"].get<double>() == 1e-17);
  CHECK(parsed.contains("rms_strain_error"));
  CHECK_FALSE(parsed.contains("velocities"));
  CHECK_FALSE(parsed.contains("dt"));
}

TEST_CASE("OBJ text: vertices, then faces or, without triangles, lines", "[common][output]") {
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 3);
  x(0, 1) = 1.0;
  x(1, 2) = 0.1;
  const std::string mesh = cl::obj_text(x, {cl::Triangle{0, 1, 2, 0.05}}, {cl::Spring{0, 1, 1.0}}, "mesh");
  CHECK(mesh == "# mesh\nv 0 0 0\nv 1 0 0\nv 0 0.10000000000000001 0\nf 1 2 3\n");
  const std::string rope = cl::obj_text(x, {}, {cl::Spring{0, 1, 1.0}, cl::Spring{1, 2, 1.0}}, "rope");
  CHECK(rope.substr(rope.find("l ")) == "l 1 2\nl 2 3\n");
}

// Tests of the Abaqus and Gmsh tetrahedral mesh readers, on a real liver mesh, on tiny hand-written
// cubes, and on broken copies of both.

#include "liversim/engine/mesh_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace liversim {
namespace {

namespace fs = std::filesystem;

const fs::path kDataDir = LIVERSIM_TEST_DATA_DIR;
const fs::path kLiverPath =
    fs::path(LIVERSIM_SHARED_DIR) / "data" / "external" / "zhang-liver" / "Liver_Iso.inp";

// A directory per test (ctest runs the tests of this file in parallel processes, and cases of a
// parameterised test write files of the same name).
fs::path output_path(const std::string& name) {
  const testing::TestInfo* test = testing::UnitTest::GetInstance()->current_test_info();
  std::string folder = test ? std::string(test->test_suite_name()) + "." + test->name() : "none";
  for (char& c : folder)
    if (c == '/') c = '_';
  const fs::path dir = fs::path(LIVERSIM_TEST_OUTPUT_DIR) / "mesh_io" / folder;
  fs::create_directories(dir);
  return dir / name;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path write_text(const std::string& name, const std::string& text) {
  const fs::path path = output_path(name);
  // A new file is much cheaper than truncating the old one, which ext4 flushes to disk first.
  fs::remove(path);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A line of a file's text: where it starts and ends (before "\r\n") and its 1-based number.
struct TextLine {
  std::size_t begin = std::string::npos, end = std::string::npos;
  int number = 0;
  std::string_view text(const std::string& s) const { return {s.data() + begin, end - begin}; }
};

// The first line after line `after` whose text, without leading blanks, starts with prefix.
TextLine find_line(const std::string& text, const std::string& prefix, int after = 0) {
  std::size_t begin = 0;
  for (int number = 1; begin < text.size(); ++number) {
    auto end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const auto line_end = (end > begin && text[end - 1] == '\r') ? end - 1 : end;
    const auto first = text.find_first_not_of(' ', begin);
    if (number > after && first < line_end && text.compare(first, prefix.size(), prefix) == 0)
      return {begin, line_end, number};
    begin = end + 1;
  }
  ADD_FAILURE() << "no line starts with '" << prefix << "'";
  return {};
}

std::string replace_line(std::string text, const TextLine& line, const std::string& replacement) {
  return text.replace(line.begin, line.end - line.begin, replacement);
}

// Runs read and returns the MeshReadError it throws.
MeshReadError read_error(const std::function<void()>& read) {
  try {
    read();
  } catch (const MeshReadError& e) {
    return e;
  }
  ADD_FAILURE() << "no MeshReadError was thrown";
  return MeshReadError("", 0, "");
}

testing::AssertionResult mentions(const MeshReadError& e, const std::string& words) {
  if (e.message().find(words) != std::string::npos) return testing::AssertionSuccess();
  return testing::AssertionFailure() << "'" << e.what() << "' does not contain '" << words << "'";
}

double total_volume(const TetMesh& mesh) {
  double sum = 0.0;
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) sum += mesh.rest_volume_m3(e);
  return sum;
}

void expect_all_positive(const TetMesh& mesh) {
  for (std::size_t e = 0; e < mesh.tet_count(); ++e)
    EXPECT_GT(mesh.rest_volume_m3(e), 0.0) << "element index " << e;
}

void expect_same_mesh(const TetMesh& a, const TetMesh& b) {
  EXPECT_EQ(a.rest_position_m.x, b.rest_position_m.x);
  EXPECT_EQ(a.rest_position_m.y, b.rest_position_m.y);
  EXPECT_EQ(a.rest_position_m.z, b.rest_position_m.z);
  EXPECT_EQ(a.corner, b.corner);
  EXPECT_EQ(a.region, b.region);
  EXPECT_EQ(a.node_sets, b.node_sets);
  EXPECT_EQ(a.element_sets, b.element_sets);
}

// ---------------------------------------------------------------------------------------------
// The real liver, checked against an independent, deliberately simple reading of its text.

struct LiverText {
  std::map<long, std::array<double, 3>> nodes;
  std::vector<std::pair<long, std::array<long, 4>>> elements;  // in file order
  std::map<std::string, std::size_t> node_set_size;            // plain (non-generate) sets only
};

LiverText parse_liver_independently() {
  LiverText liver;
  std::istringstream in(read_text(kLiverPath));
  std::string line, section, set_name;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("*", 0) == 0) {
      section = line;
      set_name.clear();
      if (line.rfind("*Nset, nset=", 0) == 0 && line.find("generate") == std::string::npos)
        set_name = line.substr(12);
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    if (section == "*Node") {
      long id;
      std::array<double, 3> p;
      fields >> id >> p[0] >> p[1] >> p[2];
      liver.nodes[id] = p;
    } else if (section == "*Element, type=C3D4T") {
      long id;
      std::array<long, 4> n;
      fields >> id >> n[0] >> n[1] >> n[2] >> n[3];
      liver.elements.push_back({id, n});
    } else if (!set_name.empty()) {
      long id;
      while (fields >> id) ++liver.node_set_size[set_name];
    }
  }
  return liver;
}

double tet_volume(const std::array<double, 3>& a, const std::array<double, 3>& b,
                  const std::array<double, 3>& c, const std::array<double, 3>& d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6.0;
}

TEST(MeshIoLiver, MatchesAnIndependentReadingOfTheFile) {
  const TetMesh mesh = read_abaqus_inp(kLiverPath);
  const LiverText liver = parse_liver_independently();
  ASSERT_EQ(liver.nodes.size(), 935u);
  ASSERT_EQ(liver.elements.size(), 4408u);
  ASSERT_EQ(mesh.node_count(), 935u);
  ASSERT_EQ(mesh.tet_count(), 4408u);

  // Node ids run 1..935 in file order, so node id k is dense index k-1.
  std::size_t i = 0;
  for (const auto& [id, p] : liver.nodes) {
    ASSERT_EQ(id, static_cast<long>(i) + 1);
    EXPECT_EQ(mesh.rest_position_m.at(i), Eigen::Vector3d(p[0], p[1], p[2]));
    ++i;
  }
  // Same corners as written (the reader may swap two to fix the winding).
  double independent_volume = 0.0;
  for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
    const auto& [id, n] = liver.elements[e];
    std::array<long, 4> written = n, read{};
    for (int c = 0; c < 4; ++c) read[c] = mesh.corner[c][e] + 1;
    std::sort(written.begin(), written.end());
    std::sort(read.begin(), read.end());
    EXPECT_EQ(read, written) << "element " << id;
    independent_volume += std::abs(tet_volume(liver.nodes.at(n[0]), liver.nodes.at(n[1]),
                                              liver.nodes.at(n[2]), liver.nodes.at(n[3])));
  }
  expect_all_positive(mesh);
  // Every element is right side out, so the sum of signed volumes equals the independently
  // computed sum of absolute volumes (up to summation rounding).
  EXPECT_NEAR(total_volume(mesh), independent_volume, 1e-12 * independent_volume);
  // The data set's README gives "volume ≈ 1.75 L".
  EXPECT_NEAR(total_volume(mesh), 1.75e-3, 0.005e-3);
}

TEST(MeshIoLiver, HasTheNamedSetsOfTheFile) {
  const TetMesh mesh = read_abaqus_inp(kLiverPath);
  const LiverText liver = parse_liver_independently();
  ASSERT_EQ(liver.node_set_size.at("Disp"), 41u);
  ASSERT_EQ(liver.node_set_size.at("FixT&P"), 63u);
  EXPECT_EQ(mesh.node_sets.at("Disp").size(), 41u);
  EXPECT_EQ(mesh.node_sets.at("FixT&P").size(), 63u);
  EXPECT_EQ(mesh.node_sets.at("Disp").front(), 71);    // node 72
  EXPECT_EQ(mesh.node_sets.at("FixT&P").back(), 310);  // node 311
  EXPECT_EQ(mesh.node_sets.at("T0").size(), 935u);
  EXPECT_EQ(mesh.node_sets.at("_PickedSet28").size(), 935u);
  EXPECT_EQ(mesh.node_sets.size(), 4u);
  EXPECT_EQ(mesh.element_sets.at("BodyHFlux").size(), 187u);
  EXPECT_EQ(mesh.element_sets.at("BodyHFlux").back(), 186);
  EXPECT_EQ(mesh.element_sets.at("Grav").size(), 4408u);
  EXPECT_EQ(mesh.element_sets.at("Metabo").size(), 4408u);
  EXPECT_EQ(mesh.element_sets.at("_PickedSet28").size(), 4408u);
  EXPECT_EQ(mesh.element_sets.size(), 4u);
}

TEST(MeshIoLiver, ReadingTwiceGivesTheSameMesh) {
  expect_same_mesh(read_abaqus_inp(kLiverPath), read_abaqus_inp(kLiverPath));
}

TEST(MeshIoLiver, LineEndingsDoNotMatter) {
  std::string text = read_text(kLiverPath);
  ASSERT_NE(text.find("\r\n"), std::string::npos);  // the file as published uses CRLF
  std::erase(text, '\r');
  expect_same_mesh(read_abaqus_inp(write_text("liver_lf.inp", text)), read_abaqus_inp(kLiverPath));
}

TEST(MeshIoLiver, LoadsQuickly) {
  const auto start = std::chrono::steady_clock::now();
  const TetMesh mesh = read_tet_mesh(kLiverPath);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(mesh.tet_count(), 4408u);
#if defined(NDEBUG) && !defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(ms, 100.0);
#else
  EXPECT_LT(ms, 1000.0);  // unoptimised or sanitised builds run several times slower
#endif
  RecordProperty("load_ms", std::to_string(ms));
}

// ---------------------------------------------------------------------------------------------
// Broken copies of the liver

class MeshIoLiverBroken : public testing::Test {
 protected:
  void SetUp() override { text_ = read_text(kLiverPath); }

  MeshReadError error_for(const std::string& name, const std::string& text) {
    return read_error([&] { read_abaqus_inp(write_text(name, text)); });
  }

  std::string text_;
};

TEST_F(MeshIoLiverBroken, CutInsideAnElementLineNamesThatLine) {
  const TextLine line = find_line(text_, "4405,");
  const std::string cut = text_.substr(0, line.begin) + "4405, 670,  60";
  const auto e = error_for("cut_mid_line.inp", cut);
  EXPECT_EQ(e.line(), line.number);
  EXPECT_TRUE(mentions(e, "element 4405: expected an element id and 4 node ids, found 3 fields"));
}

// Abaqus files have no counts or section ends, so a file cut between lines cannot be told from a
// shorter mesh: the complete elements load, consistently, and the sets (after them) are absent.
TEST_F(MeshIoLiverBroken, CutBetweenElementLinesLoadsTheCompleteElements) {
  const TextLine line = find_line(text_, "2000,");
  const TetMesh mesh = read_abaqus_inp(write_text("cut_at_line.inp", text_.substr(0, line.end)));
  EXPECT_EQ(mesh.node_count(), 935u);
  EXPECT_EQ(mesh.tet_count(), 2000u);
  EXPECT_TRUE(mesh.node_sets.empty());
  EXPECT_TRUE(mesh.element_sets.empty());
  expect_all_positive(mesh);
}

TEST_F(MeshIoLiverBroken, CoordinateThatIsNotANumber) {
  const TextLine line = find_line(text_, "12,");
  const auto e =
      error_for("abc.inp", replace_line(text_, line, "     12, abc,  0.180000007,  0.358956665"));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_EQ(e.message(), "node 12: coordinate 'abc' is not a number");
}

TEST_F(MeshIoLiverBroken, CoordinateThatIsNotFinite) {
  const TextLine line = find_line(text_, "20,");
  const auto e = error_for("nan.inp", replace_line(text_, line, "20, 0.1, nan, 0.3"));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_TRUE(mentions(e, "node 20: coordinate 'nan' is not a finite number"));
}

TEST_F(MeshIoLiverBroken, NodeLineWithTooFewFields) {
  const TextLine line = find_line(text_, "30,");
  const auto e = error_for("short_node.inp", replace_line(text_, line, "30, 0.1, 0.2"));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_TRUE(mentions(e, "node 30: expected a node id and 3 coordinates, found 3 fields"));
}

TEST_F(MeshIoLiverBroken, ElementReferringToAnUndefinedNode) {
  const TextLine line = find_line(text_, "5, 418, 415, 419, 416");
  const auto e =
      error_for("undefined_node.inp", replace_line(text_, line, "5, 418, 415, 419, 99999"));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_EQ(e.message(), "element 5 refers to node 99999, which is not defined");
}

TEST_F(MeshIoLiverBroken, DuplicatedNodeId) {
  const TextLine first = find_line(text_, "12,");
  const TextLine line = find_line(text_, "13,");
  const std::string coordinates(line.text(text_).substr(line.text(text_).find(',')));
  const auto e = error_for("duplicate_node.inp", replace_line(text_, line, "12" + coordinates));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_EQ(e.message(),
            "node 12 is defined twice (first on line " + std::to_string(first.number) + ")");
}

TEST_F(MeshIoLiverBroken, DuplicatedElementId) {
  const TextLine line = find_line(text_, "7,", find_line(text_, "*Element").number);
  const auto e = error_for("duplicate_element.inp", replace_line(text_, line, "6, 1, 2, 3, 4"));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_TRUE(mentions(e, "element 6 is defined twice"));
}

TEST_F(MeshIoLiverBroken, ElementWithTwoEqualCorners) {
  const TextLine line = find_line(text_, "17,", find_line(text_, "*Element").number);
  std::string text(line.text(text_));  // "17, a, b, c, d": make c equal to b
  const auto a = text.find(',') + 1, b = text.find(',', a) + 1, c = text.find(',', b);
  text.replace(b, c - b, text.substr(a, b - 1 - a));
  const auto e = error_for("zero_volume.inp", replace_line(text_, line, text));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_TRUE(mentions(e, "element 17 (line " + std::to_string(line.number) + ") has zero volume"));
}

TEST_F(MeshIoLiverBroken, NoElementSection) {
  const TextLine header = find_line(text_, "*Element");
  const TextLine next = find_line(text_, "*Nset");
  const auto e =
      error_for("no_elements.inp", text_.substr(0, header.begin) + text_.substr(next.begin));
  EXPECT_EQ(e.line(), 0);
  EXPECT_TRUE(mentions(e, "no tetrahedra"));
}

TEST_F(MeshIoLiverBroken, UnsupportedElementType) {
  const TextLine line = find_line(text_, "*Element");
  const auto e = error_for("c3d10.inp", replace_line(text_, line, "*Element, type=C3D10"));
  EXPECT_EQ(e.line(), 945);
  EXPECT_EQ(line.number, 945);
  EXPECT_TRUE(mentions(e, "element type C3D10 is not supported"));
}

TEST_F(MeshIoLiverBroken, NodeSetWithAnUndefinedNode) {
  const TextLine line = find_line(text_, "72,", find_line(text_, "*Nset, nset=Disp").number);
  const auto e = error_for("set_node.inp", replace_line(text_, line, "72, 99999"));
  EXPECT_EQ(e.line(), line.number);
  EXPECT_EQ(e.message(), "node set 'Disp' refers to node 99999, which is not defined");
}

TEST(MeshIoFiles, EmptyFile) {
  for (const std::string text : {"", " \r\n\r\n  "}) {
    const auto path = write_text("empty.inp", text);
    const auto e = read_error([&] { read_tet_mesh(path); });
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.message(), "file is empty");
    EXPECT_EQ(std::string(e.what()), path.string() + ": file is empty");
  }
}

TEST(MeshIoFiles, MissingFile) {
  for (const char* name : {"missing.inp", "missing.msh"}) {
    const auto path = output_path(name);
    const auto e = read_error([&] { read_tet_mesh(path); });
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.message(), "file does not exist");
  }
}

TEST(MeshIoFiles, DirectoryIsNotAMeshFile) {
  const auto e = read_error([] { read_gmsh_msh(kDataDir); });
  EXPECT_TRUE(mentions(e, "is a directory"));
}

TEST(MeshIoFiles, ExtensionChoosesTheReader) {
  EXPECT_EQ(read_tet_mesh(kDataDir / "cube_sparse.inp").tet_count(), 5u);
  EXPECT_EQ(read_tet_mesh(kDataDir / "cube_v2.msh").tet_count(), 5u);
  const auto upper_case = write_text("CUBE.MSH", read_text(kDataDir / "cube_v4.msh"));
  EXPECT_EQ(read_tet_mesh(upper_case).tet_count(), 5u);
  const auto stl = write_text("cube.stl", "solid cube\nendsolid cube\n");
  const auto e = read_error([&] { read_tet_mesh(stl); });
  EXPECT_EQ(e.line(), 0);
  EXPECT_TRUE(mentions(e, "unknown mesh file extension '.stl'"));
}

// ---------------------------------------------------------------------------------------------
// The hand-written Abaqus cube: vertex (i&1, (i>>1)&1, (i>>2)&1) has node id
// 11, 5, 42, 7, 100, 23, 64, 3; nodes are listed as 42, 5, 11, 100, 7, 3, 23, 64 and elements as
// 9, 2, 30, 4, 17.

TEST(MeshIoAbaqus, CubeWithSparseIds) {
  const TetMesh mesh = read_abaqus_inp(kDataDir / "cube_sparse.inp");
  ASSERT_EQ(mesh.node_count(), 8u);
  ASSERT_EQ(mesh.tet_count(), 5u);  // the S3 surface element is skipped
  EXPECT_EQ(mesh.rest_position_m.at(0), Eigen::Vector3d(0, 1, 0));  // node 42
  EXPECT_EQ(mesh.rest_position_m.at(7), Eigen::Vector3d(0, 1, 1));  // node 64
  expect_all_positive(mesh);
  EXPECT_NEAR(total_volume(mesh), 1.0, 1e-15);
  EXPECT_EQ(mesh.tet(0), (std::array<NodeIndex, 4>{2, 1, 0, 3}));  // 11 5 42 100
  // Element 2 (5 7 3 42) is written inside out; two corners are swapped.
  EXPECT_EQ(mesh.tet(1), (std::array<NodeIndex, 4>{1, 4, 0, 5}));
  EXPECT_EQ(mesh.tet(4), (std::array<NodeIndex, 4>{1, 0, 3, 5}));  // continued line: 5 42 100 3
  EXPECT_EQ(mesh.region, std::vector<std::int32_t>(5, 0));
}

TEST(MeshIoAbaqus, CubeSets) {
  const TetMesh mesh = read_abaqus_inp(kDataDir / "cube_sparse.inp");
  using Nodes = std::vector<NodeIndex>;
  using Tets = std::vector<TetIndex>;
  EXPECT_EQ(mesh.node_sets.at("AllNodes"), (Nodes{0, 1, 2, 3, 4, 5, 6, 7}));
  // "*NSET, NSET=bottom" adds to "Bottom": Abaqus set names ignore case.
  EXPECT_EQ(mesh.node_sets.at("Bottom"), (Nodes{0, 1, 2, 4, 7}));
  EXPECT_EQ(mesh.node_sets.at("Odd"), (Nodes{1, 4, 5}));  // generate 3, 7, 2: nodes 3, 5, 7
  EXPECT_EQ(mesh.node_sets.at("FixT&P"), (Nodes{5}));
  EXPECT_EQ(mesh.node_sets.at("Fixed"), (Nodes{1, 2}));  // assembly level, instance=Cube-1
  EXPECT_EQ(mesh.node_sets.count("AssemblyOnly"), 0u);   // names assembly-level nodes
  EXPECT_EQ(mesh.node_sets.size(), 5u);
  EXPECT_EQ(mesh.element_sets.at("Body"), (Tets{0, 1, 2, 3, 4}));
  EXPECT_EQ(mesh.element_sets.at("Even"), (Tets{1, 3}));   // generate 2, 4, 2: elements 2, 4
  EXPECT_EQ(mesh.element_sets.at("WithSkin"), (Tets{0}));  // the skipped surface is left out
  EXPECT_EQ(mesh.element_sets.count("Skin"), 0u);
  EXPECT_EQ(mesh.element_sets.size(), 3u);
}

TEST(MeshIoAbaqus, InstancePositioningIsApplied) {
  std::string text = read_text(kDataDir / "cube_sparse.inp");
  const TextLine line = find_line(text, "*Instance");
  // Move by (1, 2, 3), then turn 90 degrees about the z axis through the origin.
  text.insert(line.end + 1, " 1., 2., 3.\n 0., 0., 0., 0., 0., 1., 90.\n");
  const TetMesh mesh = read_abaqus_inp(write_text("cube_instance.inp", text));
  const Eigen::Vector3d node11 = mesh.rest_position_m.at(2);
  EXPECT_NEAR((node11 - Eigen::Vector3d(-2, 1, 3)).norm(), 0.0, 1e-15);
  expect_all_positive(mesh);
  EXPECT_NEAR(total_volume(mesh), 1.0, 1e-14);
}

TEST(MeshIoAbaqus, BrokenCubes) {
  const std::string text = read_text(kDataDir / "cube_sparse.inp");
  struct Case {
    std::string find, replacement, message;
  };
  const std::vector<Case> cases = {
      {"3, 7, 2", "3, 9, 2", "node set 'Odd' refers to node 9, which is not defined"},
      {"9, 1000", "9, 1001", "element set 'WithSkin' refers to element 1001, which is not defined"},
      {"2, 4, 2", "4, 2", "element set 'Even': generate runs backwards (4 to 2)"},
      {"*Element, type=S3", "*Element, type=C3D8", "element type C3D8 is not supported"},
      {"*Element, Type", "*Element, Tipe", "*Element has no type= parameter"},
      {"*Nset, nset=Bottom", "*Nset, nset=Bottom, elset=Nowhere",
       "node set 'Bottom' is built from element set 'Nowhere', which is not defined"},
      {"*Nset, nset=Bottom", "*Include, input=more.inp", "*Include is not supported"},
      {"*Nset, nset=FixT&P", "*Nset, nset=FixT&P\n Bottom\n*Nset, nset=X",
       "member 'Bottom' is a name; sets built from other sets are not supported"},
      {"  9, 11, 5, 42, 100", "  9, 11, 5, 42, 100, 7",
       "element 9: expected an element id and 4 node ids, found 6 fields"},
      {"  9, 11, 5, 42, 100", "  9, 11, 5, 4x2, 100", "element 9: node id '4x2' is not an integer"},
      {"  42, 0., 1., 0.", "  42, 0., 1.e999, 0.", "node 42: coordinate '1.e999' is not a finite"},
      {"  42, 0., 1., 0.", "  0, 0., 1., 0.", "node id '0' is out of range (1 to 2147483647)"},
      {"*End Part", "*Part, name=Other\n*Node\n1, 0., 0., 0.\n*End Part",
       "*Part inside another *Part"},
  };
  for (const auto& c : cases) {
    std::string broken = text;
    const auto at = broken.find(c.find);
    ASSERT_NE(at, std::string::npos) << c.find;
    broken.replace(at, c.find.size(), c.replacement);
    const auto e = read_error([&] { read_abaqus_inp(write_text("broken_cube.inp", broken)); });
    EXPECT_TRUE(mentions(e, c.message));
    EXPECT_GT(e.line(), 0) << e.what();
  }
}

TEST(MeshIoAbaqus, SecondMeshedPartIsRejected) {
  std::string text = read_text(kDataDir / "cube_sparse.inp");
  const TextLine line = find_line(text, "*End Part");
  text.insert(line.end + 1, "*Part, name=Tool\n*Node\n 1, 0., 0., 0.\n*End Part\n");
  const auto e = read_error([&] { read_abaqus_inp(write_text("two_parts.inp", text)); });
  EXPECT_EQ(e.line(), line.number + 2);
  EXPECT_TRUE(mentions(e, "a second *Part with nodes or elements"));
}

TEST(MeshIoAbaqus, FlatFileWithoutParts) {
  const std::string text =
      "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n"
      "*ELEMENT, TYPE=C3D4H, ELSET=ALL\n1, 1, 2, 3, 4\n";
  const TetMesh mesh = read_abaqus_inp(write_text("flat.inp", text));
  EXPECT_EQ(mesh.tet_count(), 1u);
  EXPECT_NEAR(mesh.rest_volume_m3(0), 1.0 / 6.0, 1e-15);
  EXPECT_EQ(mesh.element_sets.at("ALL"), std::vector<TetIndex>{0});
}

// ---------------------------------------------------------------------------------------------
// Gmsh cubes: the same cube and node tags as the Abaqus one, nodes listed 11, 5, 42, 7, 100, 23,
// 64, 3, tetrahedra 10|3, 20|4 (inside out), 30|7, 35|8, 40|9 (v4 tag | v2 tag).

void expect_cube(const TetMesh& mesh, const std::vector<std::int32_t>& regions) {
  ASSERT_EQ(mesh.node_count(), 8u);
  ASSERT_EQ(mesh.tet_count(), 5u);
  EXPECT_EQ(mesh.rest_position_m.at(0), Eigen::Vector3d(0, 0, 0));  // tag 11
  EXPECT_EQ(mesh.rest_position_m.at(7), Eigen::Vector3d(1, 1, 1));  // tag 3
  EXPECT_EQ(mesh.tet(0), (std::array<NodeIndex, 4>{0, 1, 2, 4}));
  EXPECT_EQ(mesh.tet(1), (std::array<NodeIndex, 4>{1, 3, 2, 7}));  // corners swapped
  EXPECT_EQ(mesh.region, regions);
  expect_all_positive(mesh);
  EXPECT_NEAR(total_volume(mesh), 1.0, 1e-15);
  EXPECT_TRUE(mesh.node_sets.empty());
  EXPECT_TRUE(mesh.element_sets.empty());
}

TEST(MeshIoGmsh, Version2Ascii) {
  expect_cube(read_gmsh_msh(kDataDir / "cube_v2.msh"), {1, 1, 1, 2, 2});
}

TEST(MeshIoGmsh, Version41AsciiTakesRegionsFromEntities) {
  expect_cube(read_gmsh_msh(kDataDir / "cube_v4.msh"), {7, 7, 7, 9, 9});
}

TEST(MeshIoGmsh, Version40Ascii) {
  expect_cube(read_gmsh_msh(kDataDir / "cube_v40.msh"), {7, 7, 7, 9, 9});
}

TEST(MeshIoGmsh, Version4WithoutEntitiesHasRegionZero) {
  std::string text = read_text(kDataDir / "cube_v4.msh");
  const auto begin = text.find("$Entities"), end = text.find("$EndEntities\n") + 13;
  text.erase(begin, end - begin);
  expect_cube(read_gmsh_msh(write_text("no_entities.msh", text)), {0, 0, 0, 0, 0});
}

// Binary .msh writers for the cube, laid out as Gmsh writes them (see its GModelIO_MSH2/4).
class BinaryWriter {
 public:
  explicit BinaryWriter(bool big_endian)
      : swap_(big_endian != (std::endian::native == std::endian::big)) {}
  template <class T>
  BinaryWriter& put(T value) {
    std::array<char, sizeof(T)> bytes;
    std::memcpy(bytes.data(), &value, sizeof(T));
    if (swap_) std::reverse(bytes.begin(), bytes.end());
    out_.append(bytes.data(), bytes.size());
    return *this;
  }
  BinaryWriter& text(const std::string& s) {
    out_ += s;
    return *this;
  }
  const std::string& str() const { return out_; }

 private:
  bool swap_;
  std::string out_;
};

struct CubeTet {
  std::int64_t v4_tag, v2_tag;
  std::array<std::int64_t, 4> nodes;
  int volume;  // entity 1 (physical 7) or 2 (physical 9)
};
const std::vector<std::pair<std::int64_t, std::array<double, 3>>> kCubeNodes = {
    {11, {0, 0, 0}},  {5, {1, 0, 0}},  {42, {0, 1, 0}}, {7, {1, 1, 0}},
    {100, {0, 0, 1}}, {23, {1, 0, 1}}, {64, {0, 1, 1}}, {3, {1, 1, 1}}};
const std::vector<CubeTet> kCubeTets = {{10, 3, {11, 5, 42, 100}, 1},
                                        {20, 4, {5, 7, 3, 42}, 1},
                                        {30, 7, {5, 100, 23, 3}, 1},
                                        {35, 8, {42, 100, 3, 64}, 2},
                                        {40, 9, {5, 42, 100, 3}, 2}};

std::string binary_cube_v2(bool big_endian = false) {
  BinaryWriter w(big_endian);
  w.text("$MeshFormat\n2.2 1 8\n").put<std::int32_t>(1).text("\n$EndMeshFormat\n");
  w.text("$Nodes\n8\n");
  for (const auto& [tag, p] : kCubeNodes)
    w.put<std::int32_t>(static_cast<std::int32_t>(tag)).put(p[0]).put(p[1]).put(p[2]);
  w.text("\n$EndNodes\n$Elements\n6\n");
  // A triangle (type 2) to skip, then the tetrahedra: physical and elementary tags.
  w.put<std::int32_t>(2).put<std::int32_t>(1).put<std::int32_t>(2);
  for (const std::int32_t v : {2, 10, 1, 11, 5, 42}) w.put(v);
  w.put<std::int32_t>(4).put<std::int32_t>(5).put<std::int32_t>(2);
  for (const auto& t : kCubeTets) {
    w.put<std::int32_t>(static_cast<std::int32_t>(t.v2_tag))
        .put<std::int32_t>(t.volume)
        .put<std::int32_t>(t.volume);
    for (const auto n : t.nodes) w.put<std::int32_t>(static_cast<std::int32_t>(n));
  }
  w.text("\n$EndElements\n");
  return w.str();
}

std::string binary_cube_v41(bool big_endian = false) {
  BinaryWriter w(big_endian);
  w.text("$MeshFormat\n4.1 1 8\n").put<std::int32_t>(1).text("\n$EndMeshFormat\n");
  w.text("$Entities\n");
  for (const std::uint64_t count : {0, 0, 1, 2}) w.put(count);
  w.put<std::int32_t>(1);  // surface 1: box, no physical, no bounding curves
  for (const double b : {0, 0, 0, 1, 1, 0}) w.put(b);
  w.put<std::uint64_t>(0).put<std::uint64_t>(0);
  for (const std::int32_t volume : {1, 2}) {
    w.put(volume);
    for (const double b : {0, 0, 0, 1, 1, 1}) w.put(b);
    w.put<std::uint64_t>(1).put<std::int32_t>(volume == 1 ? 7 : 9);
    w.put<std::uint64_t>(1).put<std::int32_t>(volume == 1 ? 1 : -1);
  }
  w.text("\n$EndEntities\n$Nodes\n");
  for (const std::uint64_t v : {1, 8, 3, 100}) w.put(v);
  w.put<std::int32_t>(3).put<std::int32_t>(1).put<std::int32_t>(0).put<std::uint64_t>(8);
  for (const auto& [tag, p] : kCubeNodes) w.put(static_cast<std::uint64_t>(tag));
  for (const auto& [tag, p] : kCubeNodes) w.put(p[0]).put(p[1]).put(p[2]);
  w.text("\n$EndNodes\n$Elements\n");
  for (const std::uint64_t v : {3, 6, 1, 40}) w.put(v);
  w.put<std::int32_t>(2).put<std::int32_t>(1).put<std::int32_t>(2).put<std::uint64_t>(1);
  for (const std::uint64_t v : {1, 11, 5, 42}) w.put(v);
  for (const int volume : {1, 2}) {
    w.put<std::int32_t>(3).put<std::int32_t>(volume).put<std::int32_t>(4);
    w.put<std::uint64_t>(volume == 1 ? 3 : 2);
    for (const auto& t : kCubeTets) {
      if (t.volume != volume) continue;
      w.put(static_cast<std::uint64_t>(t.v4_tag));
      for (const auto n : t.nodes) w.put(static_cast<std::uint64_t>(n));
    }
  }
  w.text("\n$EndElements\n");
  return w.str();
}

TEST(MeshIoGmsh, Version2Binary) {
  expect_cube(read_gmsh_msh(write_text("cube_v2_binary.msh", binary_cube_v2())), {1, 1, 1, 2, 2});
  expect_cube(read_gmsh_msh(write_text("cube_v2_swapped.msh", binary_cube_v2(true))),
              {1, 1, 1, 2, 2});
}

TEST(MeshIoGmsh, Version41Binary) {
  expect_cube(read_gmsh_msh(write_text("cube_v41_binary.msh", binary_cube_v41())), {7, 7, 7, 9, 9});
  expect_cube(read_gmsh_msh(write_text("cube_v41_swapped.msh", binary_cube_v41(true))),
              {7, 7, 7, 9, 9});
}

TEST(MeshIoGmsh, BinaryAndAsciiGiveTheSameMesh) {
  expect_same_mesh(read_gmsh_msh(write_text("cube_v41_binary.msh", binary_cube_v41())),
                   read_gmsh_msh(kDataDir / "cube_v4.msh"));
  expect_same_mesh(read_gmsh_msh(write_text("cube_v2_binary.msh", binary_cube_v2())),
                   read_gmsh_msh(kDataDir / "cube_v2.msh"));
}

TEST(MeshIoGmsh, ReadingTwiceGivesTheSameMesh) {
  for (const char* name : {"cube_v2.msh", "cube_v4.msh", "cube_v40.msh"})
    expect_same_mesh(read_gmsh_msh(kDataDir / name), read_gmsh_msh(kDataDir / name));
}

struct BrokenMsh {
  std::string file, find, replacement, message;
  int line;  // expected error line; 0 when not tied to a line
};

class MeshIoGmshBroken : public testing::TestWithParam<BrokenMsh> {};

TEST_P(MeshIoGmshBroken, ThrowsAClearError) {
  const BrokenMsh& c = GetParam();
  std::string text = read_text(kDataDir / c.file);
  const auto at = text.find(c.find);
  ASSERT_NE(at, std::string::npos) << c.find;
  text.replace(at, c.find.size(), c.replacement);
  const auto e = read_error([&] { read_gmsh_msh(write_text("broken.msh", text)); });
  EXPECT_TRUE(mentions(e, c.message));
  EXPECT_EQ(e.line(), c.line) << e.what();
}

INSTANTIATE_TEST_SUITE_P(
    MeshIoGmshBroken, MeshIoGmshBroken,
    testing::Values(
        BrokenMsh{"cube_v2.msh", "$EndElements\n", "",
                  "the file ends inside $Elements (no $EndElements; truncated file?)", 30},
        BrokenMsh{"cube_v4.msh", "$EndElements\n", "",
                  "the file ends inside $Elements (no $EndElements; truncated file?)", 46},
        BrokenMsh{"cube_v2.msh", "2.2 0 8", "5.0 0 8",
                  "unsupported .msh version '5.0'; this reader handles 2.2, 4.0 and 4.1", 2},
        BrokenMsh{"cube_v4.msh", "4.1 0 8", "3.0 0 8", "unsupported .msh version '3.0'", 2},
        BrokenMsh{"cube_v2.msh", "$Nodes\n8\n", "$Nodes\n9\n",
                  "$Nodes declares 9 nodes but lists 8 before '$EndNodes'", 20},
        BrokenMsh{"cube_v2.msh", "$Nodes\n8\n", "$Nodes\n7\n",
                  "expected $EndNodes after the declared entries, found '3 1 1 1'", 19},
        BrokenMsh{"cube_v4.msh", "2 8 3 100", "2 9 3 100",
                  "$Nodes declares 9 nodes but lists 8 in its blocks", 16},
        BrokenMsh{"cube_v4.msh", "3 2 0 3\n", "3 2 0 4\n",
                  "$Nodes block on line 28: expected one node tag per line, found '1 0 1'", 32},
        BrokenMsh{"cube_v40.msh", "2 3 0 3\n", "2 3 0 4\n",
                  "$Nodes has a block that declares 4 nodes but lists 3 before '$EndNodes'", 21},
        BrokenMsh{"cube_v2.msh", "\n9 4 2 2 2 5 42 100 3", "\n9 4 2 2 2 5 42 100 99",
                  "element 9 refers to node 99, which is not defined", 29},
        BrokenMsh{"cube_v2.msh", "\n9 4 2 2 2 5 42 100 3", "\n9 4 2 2 2 5 42 100",
                  "element 9: a 4-node tetrahedron with 2 tags needs 9 fields, found 8", 29},
        BrokenMsh{"cube_v2.msh", "\n9 4 2 2 2 5 42 100 3", "\n9 4 2 2 2 5 42 42 3",
                  "element 9 (line 29) has zero volume", 29},
        BrokenMsh{"cube_v2.msh", "\n8 4 2 2 2", "\n7 4 2 2 2",
                  "element 7 is defined twice (first on line 27)", 28},
        BrokenMsh{"cube_v2.msh", "\n64 0 1 1", "\n5 0 1 1",
                  "node 5 is defined twice (first on line 13)", 18},
        BrokenMsh{"cube_v4.msh", "\n0 1 1\n", "\n0 one 1\n",
                  "node 64: coordinate 'one' is not a number", 33},
        BrokenMsh{"cube_v40.msh", "\n64 0 1 1", "\n64 0 1",
                  "node 64: expected a node tag and 3 coordinates, found 3 fields", 19},
        BrokenMsh{"cube_v4.msh", "$MeshFormat", "$Mesh", "not a Gmsh mesh", 1},
        BrokenMsh{"cube_v4.msh", "4.1 0 8", "4.1 1 4", "data-size '4' is not supported", 2},
        BrokenMsh{"cube_v40.msh", "4 0 8", "4 1 8", "binary .msh 4.0 is not supported", 2},
        BrokenMsh{"cube_v4.msh", "$Elements\n3 6 1 40", "$Elements\n3 7 1 40",
                  "$Elements declares 7 elements but lists 6 in its blocks", 37},
        BrokenMsh{"cube_v2.msh", "$Elements\n8\n1 1", "$Elements\n8\n1 x",
                  "element 1: type 'x' is not an integer", 23},
        BrokenMsh{"cube_v4.msh", "$EndNodes\n", "$EndNodes\n$EndElements\n",
                  "'$EndElements' without a matching $Elements", 36},
        BrokenMsh{"cube_v4.msh", "$Entities", "$PartitionedEntities",
                  "partitioned meshes are not supported", 9}));

TEST(MeshIoGmsh, OnlySurfaceElements) {
  std::string text = read_text(kDataDir / "cube_v4.msh");
  const auto begin = text.find("$Elements"), end = text.find("$EndElements");
  text.replace(begin, end - begin, "$Elements\n1 1 1 1\n2 1 2 1\n1 11 5 42\n");
  const auto e = read_error([&] { read_gmsh_msh(write_text("surface_only.msh", text)); });
  EXPECT_EQ(e.line(), 0);
  EXPECT_EQ(e.message(), "no tetrahedra: the file has no elements of type 4 (4-node tetrahedron)");
}

TEST(MeshIoGmsh, TruncatedBinaryFiles) {
  for (const std::string& full : {binary_cube_v2(), binary_cube_v41()}) {
    const std::string cut = full.substr(0, full.find("$EndElements") - 20);
    const auto e = read_error([&] { read_gmsh_msh(write_text("cut_binary.msh", cut)); });
    EXPECT_TRUE(mentions(e, "(truncated file?)"));
  }
  std::string huge_count = binary_cube_v41();
  const auto nodes = huge_count.find("$Nodes\n") + 7;
  const std::uint64_t absurd = std::uint64_t{1} << 60;
  std::memcpy(huge_count.data() + nodes + 8, &absurd, 8);  // numNodes: harmless, checked later
  std::memcpy(huge_count.data() + nodes + 32 + 12, &absurd, 8);  // block size: checked first
  const auto e = read_error([&] { read_gmsh_msh(write_text("absurd.msh", huge_count)); });
  EXPECT_TRUE(mentions(e, "more than the rest of the file holds"));
}

// ---------------------------------------------------------------------------------------------
// Garbage must end in a MeshReadError, never a crash, a hang or another exception.

void expect_only_mesh_read_errors(const std::string& name, const std::string& text) {
  const auto path = write_text(name, text);
  try {
    read_tet_mesh(path);
  } catch (const MeshReadError&) {
  } catch (const std::exception& e) {
    ADD_FAILURE() << "unexpected exception: " << e.what() << "\n" << text;
  }
}

TEST(MeshIoRobustness, EveryPrefixOfEveryFile) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"prefix.inp", read_text(kDataDir / "cube_sparse.inp")},
      {"prefix.msh", read_text(kDataDir / "cube_v2.msh")},
      {"prefix.msh", read_text(kDataDir / "cube_v4.msh")},
      {"prefix.msh", read_text(kDataDir / "cube_v40.msh")},
      {"prefix.msh", binary_cube_v2()},
      {"prefix.msh", binary_cube_v41()}};
  for (const auto& [name, text] : files)
    for (std::size_t n = 0; n < text.size(); ++n)
      expect_only_mesh_read_errors(name, text.substr(0, n));
}

TEST(MeshIoRobustness, RandomByteChanges) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"mutant.inp", read_text(kDataDir / "cube_sparse.inp")},
      {"mutant.msh", read_text(kDataDir / "cube_v2.msh")},
      {"mutant.msh", read_text(kDataDir / "cube_v4.msh")},
      {"mutant.msh", binary_cube_v2()},
      {"mutant.msh", binary_cube_v41()}};
  std::mt19937 random(20240521);
  const std::string interesting = "0123456789-+.,eE$*\n\r \t=9";
  for (const auto& [name, text] : files)
    for (int trial = 0; trial < 400; ++trial) {
      std::string mutant = text;
      const int changes = 1 + static_cast<int>(random() % 4);
      for (int k = 0; k < changes; ++k) {
        const auto at = random() % mutant.size();
        mutant[at] = (random() % 2) ? interesting[random() % interesting.size()]
                                    : static_cast<char>(random() % 256);
      }
      expect_only_mesh_read_errors(name, mutant);
    }
}

TEST(MeshIoTetMesh, SignedVolume) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(0, 0, 1);
  EXPECT_DOUBLE_EQ(signed_tet_volume(a, b, c, d), 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(signed_tet_volume(a, c, b, d), -1.0 / 6.0);
  TetMesh mesh;
  for (const auto& p : {a, b, c, d}) mesh.rest_position_m.push_back(2.0 * p);
  mesh.add_tet({0, 1, 2, 3});
  EXPECT_DOUBLE_EQ(mesh.rest_volume_m3(0), 8.0 / 6.0);
}

}  // namespace
}  // namespace liversim

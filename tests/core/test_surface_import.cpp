// Surface models (issue 9): the real liver of ../shared (Zhang's Liver_Iso.inp, its boundary)
// written through assimp's exporters in every format the importer reads, read back, and
// tetrahedralised by Gmsh at a requested count; broken surfaces refused, naming what and where.
#include "liversim/engine/mesh_io.h"
#include "liversim/engine/mesh_quality.h"
#include "liversim/engine/surface.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/surface_import.h"
#include "liversim/scenario/scenario.h"

#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <assimp/Exporter.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

namespace liversim {
namespace {

namespace fs = std::filesystem;

const fs::path kLiverFile =
    fs::path(LIVERSIM_SHARED_DIR) / "data/external/zhang-liver/Liver_Iso.inp";

TriangleSurface liver_surface() {
  const TetMesh mesh = read_tet_mesh(kLiverFile);
  const BoundarySurface boundary = extract_surface(mesh);
  TriangleSurface surface;
  for (NodeIndex n : boundary.nodes) surface.vertices_m.push_back(mesh.rest_position_m.at(n));
  surface.triangles = boundary.triangles;
  return surface;
}

// Writes `surface`, its lengths multiplied by `units_per_metre`, with assimp's exporter `format`.
void export_surface(const TriangleSurface& surface, double units_per_metre, const char* format,
                    const fs::path& file) {
  aiScene scene;
  scene.mRootNode = new aiNode();
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mRootNode->mNumMeshes = 1;
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene.mNumMaterials = 1;
  auto* mesh = new aiMesh();
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mMaterialIndex = 0;
  mesh->mNumVertices = static_cast<unsigned>(surface.vertices_m.size());
  mesh->mVertices = new aiVector3D[mesh->mNumVertices];
  for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
    const Eigen::Vector3d p = surface.vertices_m[v] * units_per_metre;
    mesh->mVertices[v] = aiVector3D(static_cast<ai_real>(p.x()), static_cast<ai_real>(p.y()),
                                    static_cast<ai_real>(p.z()));
  }
  mesh->mNumFaces = static_cast<unsigned>(surface.triangles.size());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
    mesh->mFaces[f].mNumIndices = 3;
    mesh->mFaces[f].mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k)
      mesh->mFaces[f].mIndices[k] = static_cast<unsigned>(surface.triangles[f][k]);
  }
  scene.mMeshes = new aiMesh* [1] { mesh };
  scene.mNumMeshes = 1;
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(&scene, format, file.string()), aiReturn_SUCCESS)
      << format << ": " << exporter.GetErrorString();
}

class SurfaceImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ =
        fs::temp_directory_path() /
        ("liversim-surface-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }
  fs::path folder_;
};

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

// Every format, in millimetres as a model from a modelling package would be: read back in metres,
// the same closed surface. The formats keep single-precision coordinates, so each vertex is good
// to about 2⁻²⁴ of 400 mm; the enclosed volume to a few times that relative.
TEST_F(SurfaceImportTest, TheRealLiverReadsBackFromEveryFormat) {
  const TriangleSurface liver = liver_surface();
  ASSERT_TRUE(surface_problems(liver).empty()) << joined(surface_problems(liver));
  const double volume_m3 = liver.volume_m3();
  ASSERT_GT(volume_m3, 0.0);
  const std::pair<const char*, const char*> formats[] = {
      {"obj", "liver.obj"},  {"stlb", "liver.stl"}, {"plyb", "liver.ply"}, {"gltf2", "liver.gltf"},
      {"glb2", "liver.glb"}, {"fbxa", "liver.fbx"}, {"3ds", "liver.3ds"}};
  ASSERT_EQ(std::size(formats), surface_file_extensions().size());
  for (const auto& [format, name] : formats) {
    SCOPED_TRACE(name);
    const fs::path file = folder_ / name;
    export_surface(liver, 1000.0, format, file);
    EXPECT_TRUE(is_surface_file(file));
    TriangleSurface read = read_surface_file(file, 1e-3);
    orient_outward(read);
    EXPECT_EQ(read.vertices_m.size(), liver.vertices_m.size());
    EXPECT_EQ(read.triangles.size(), liver.triangles.size());
    EXPECT_TRUE(surface_problems(read).empty()) << joined(surface_problems(read));
    EXPECT_NEAR(read.volume_m3(), volume_m3, 1e-5 * volume_m3);
  }
}

// Gmsh keeps the model's triangles as the boundary, so the elements fill exactly the volume the
// surface encloses (to round-off), all positively oriented, at the count asked within 5 %.
TEST_F(SurfaceImportTest, TheLiverIsTetrahedralisedAtTheRequestedCountFillingItsVolume) {
  const TriangleSurface liver = liver_surface();
  for (const int target : {2000, 6000}) {
    SCOPED_TRACE(target);
    SurfaceMeshingOptions options;
    options.target_tet_count = target;
    int reports = 0;
    options.progress = [&](const MeshingProgress& progress) {
      ++reports;
      EXPECT_GE(progress.attempt, 1);
      EXPECT_LE(progress.attempt, progress.max_attempts);
      EXPECT_GT(progress.element_size_mm, 0.0);
      return true;
    };
    const TetMesh mesh = tetrahedralise_surface(liver, options);
    EXPECT_NEAR(static_cast<double>(mesh.tet_count()), target, 0.05 * target);
    EXPECT_GE(reports, 2);
    double volume_m3 = 0.0;
    double smallest_m3 = std::numeric_limits<double>::infinity();
    for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
      volume_m3 += mesh.rest_volume_m3(e);
      smallest_m3 = std::min(smallest_m3, mesh.rest_volume_m3(e));
    }
    EXPECT_GT(smallest_m3, 0.0);
    EXPECT_NEAR(volume_m3, liver.volume_m3(), 1e-9 * liver.volume_m3());
    const MeshQualityReport quality = assess_quality(mesh);
    EXPECT_EQ(quality.inverted_count, 0u);
    EXPECT_EQ(quality.degenerate_count, 0u);
  }
}

TEST_F(SurfaceImportTest, CancellingTheMeshingStopsIt) {
  SurfaceMeshingOptions options;
  options.target_tet_count = 3000;
  options.progress = [](const MeshingProgress&) { return false; };
  EXPECT_THROW(tetrahedralise_surface(liver_surface(), options), SurfaceMeshingCancelled);
}

// Broken surfaces: each refused with what is wrong and where (in mm).
TEST_F(SurfaceImportTest, BrokenSurfacesAreRefusedNamingTheProblemAndWhere) {
  const TriangleSurface liver = liver_surface();
  auto problems_of = [](const TriangleSurface& s) { return joined(surface_problems(s)); };

  TriangleSurface holed = liver;
  holed.triangles.pop_back();
  EXPECT_NE(problems_of(holed).find("not closed: a hole's edge at ("), std::string::npos)
      << problems_of(holed);
  EXPECT_NE(problems_of(holed).find(") mm"), std::string::npos);
  SurfaceMeshingOptions options;
  options.target_tet_count = 2000;
  try {
    tetrahedralise_surface(holed, options);
    ADD_FAILURE() << "a surface with a hole was meshed";
  } catch (const SurfaceImportError& e) {
    EXPECT_NE(std::string(e.what()).find("bounds no solid"), std::string::npos) << e.what();
  }

  TriangleSurface flipped = liver;
  std::swap(flipped.triangles[10][1], flipped.triangles[10][2]);
  EXPECT_NE(problems_of(flipped).find("inconsistent orientation"), std::string::npos)
      << problems_of(flipped);

  // Two copies of the liver, the second moved by a centimetre: they cross each other.
  TriangleSurface overlapping = liver;
  const auto offset = static_cast<std::int32_t>(liver.vertices_m.size());
  for (const Eigen::Vector3d& v : liver.vertices_m)
    overlapping.vertices_m.push_back(v + Eigen::Vector3d(0.01, 0.0, 0.0));
  for (auto t : liver.triangles)
    overlapping.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  EXPECT_NE(problems_of(overlapping).find("intersects itself"), std::string::npos)
      << problems_of(overlapping);
  // The same two apart are two solids, and fine.
  TriangleSurface apart = overlapping;
  for (std::size_t v = liver.vertices_m.size(); v < apart.vertices_m.size(); ++v)
    apart.vertices_m[v].x() += 1.0;
  EXPECT_EQ(problems_of(apart), "");

  // Files: missing, not a model, no triangles, a bad unit.
  EXPECT_THROW(read_surface_file(folder_ / "missing.stl", 1e-3), SurfaceImportError);
  const fs::path garbage = folder_ / "garbage.obj";
  std::ofstream(garbage) << "this is not a model\n";
  try {
    read_surface_file(garbage, 1e-3);
    ADD_FAILURE() << "a text file was read as a model";
  } catch (const SurfaceImportError& e) {
    EXPECT_NE(std::string(e.what()).find("garbage.obj"), std::string::npos) << e.what();
  }
  const fs::path points = folder_ / "points.obj";
  std::ofstream(points) << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_THROW(read_surface_file(points, 1e-3), SurfaceImportError);
  EXPECT_THROW(read_surface_file(points, std::nan("")), SurfaceImportError);
}

// Found by fuzzing (docs/fuzzing.md): a PLY face that lists no corners made assimp's own steps
// crash (its primitive sort) or abort (its triangulation), one of 293 840 corners took them 100 s;
// and assimp hands on a corner past the vertices unchecked. Each is refused before those steps,
// naming the face.
TEST_F(SurfaceImportTest, FacesWithoutCornersOrWithCornersPastTheVerticesAreRefused) {
  // A tetrahedron, 10 mm, its faces outward, and `extra` faces after them.
  const auto error_of = [&](const std::string& name, const std::vector<std::string>& extra) {
    const fs::path file = folder_ / name;
    std::ofstream ply(file);
    ply << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        << "property float z\nelement face " << 4 + extra.size()
        << "\nproperty list int int vertex_index\nend_header\n"
        << "0 0 0\n10 0 0\n0 10 0\n0 0 10\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    for (const std::string& face : extra) ply << face << "\n";
    ply.close();
    try {
      read_surface_file(file, 1e-3);
    } catch (const SurfaceImportError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of("whole.ply", {}), "");
  EXPECT_EQ(error_of("no-corners.ply", {"0"}),
            (folder_ / "no-corners.ply").string() +
                ": cannot read it as a surface model: face 5 of mesh 1 has no corners");
  EXPECT_EQ(error_of("corner-past.ply", {"3 1 2 9"}),
            (folder_ / "corner-past.ply").string() +
                ": cannot read it as a surface model: face 5 of mesh 1 has a corner at vertex 10, "
                "but the mesh has 4 vertices");
  // A damaged count makes a face of a huge number of corners, which assimp's steps would take
  // minutes over (time growing with its square).
  std::string huge = "5000";
  for (int k = 0; k < 5000; ++k) huge += k % 2 ? " 1" : " 2";
  EXPECT_EQ(error_of("huge-face.ply", {huge}),
            (folder_ / "huge-face.ply").string() +
                ": cannot read it as a surface model: face 5 of mesh 1 has 5000 corners, more "
                "than the 4096 a model's face may have (a damaged file?)");
}

// Found by fuzzing (docs/fuzzing.md): Debian's assimp 5.2 reads a PLY header that never ends (a
// cut-short file, or one with a blank line before "ply") forever, corrupts its heap on an element
// declared twice, reads forever for a count the file cannot hold, and asks for gigabytes for a
// damaged list count. A PLY file's header
// and its data against the header are checked before assimp sees it.
TEST_F(SurfaceImportTest, APlyFileWithADamagedHeaderIsRefusedBeforeAssimpReadsIt) {
  const auto error_of = [&](const std::string& name, const std::string& text) {
    const fs::path file = folder_ / name;
    std::ofstream(file, std::ios::binary) << text;
    try {
      read_surface_file(file, 1e-3);
    } catch (const SurfaceImportError& e) {
      const std::string prefix = file.string() + ": cannot read it as a surface model: ";
      const std::string what = e.what();
      return what.starts_with(prefix) ? what.substr(prefix.size()) : what;
    }
    return std::string();
  };
  const std::string tetrahedron_body =
      "0 0 0\n10 0 0\n0 10 0\n0 0 10\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4\nproperty list uchar int vertex_index\n";
  EXPECT_EQ(error_of("sound.ply", header + "end_header\n" + tetrahedron_body), "");
  // assimp takes "ply" after blank lines too, and reads any .ply file as PLY.
  EXPECT_EQ(error_of("blank-first.ply", "\n" + header),
            "line 1 of its PLY header is '', not 'ply' (the first line of a PLY file)");
  EXPECT_EQ(error_of("not-ply.ply", "solid cube\nendsolid cube\n"),
            "line 1 of its PLY header is 'solid cube', not 'ply' (the first line of a PLY file)");
  EXPECT_EQ(error_of("cut-short.ply", header),
            "its PLY header has no end_header line (a cut-short file?)");
  EXPECT_EQ(
      error_of("element-twice.ply",
               header + "element vertex 8\nproperty float x\nend_header\n" + tetrahedron_body),
      "line 9 of its PLY header declares the element 'vertex' a second time");
  EXPECT_EQ(error_of("count-beyond.ply",
                     "ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\n"
                     "property float x\nend_header\n" +
                         std::string(4, '\0')),
            "its PLY header declares 2000000000 of the element 'vertex', more than the 4 bytes "
            "after the header hold (a damaged file?)");
  // The data against the header: a list count beyond its type made assimp ask for gigabytes.
  EXPECT_EQ(error_of("count-past-type.ply", header + "end_header\n" +
                                                "0 0 0\n10 0 0\n0 10 0\n0 0 10\n3 0 2 1\n"
                                                "3 0 1 3\n3 0 3 2\n999999999999 1 2 3\n"),
            "line 17 (face 4 of 4): the count of its list 'vertex_index' is '999999999999', "
            "expected 0 to 255");
  EXPECT_EQ(error_of("binary-cut.ply",
                     "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                     "property list uchar int vertex_index\nend_header\n\xc8" +
                         std::string(8, '\0')),
            "its PLY data ends inside face 1 of 1");
  EXPECT_EQ(error_of("short-line.ply",
                     header + "end_header\n" +
                         "0 0 0\n10 0\n0 10 0\n0 0 10\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"),
            "line 11 (vertex 2 of 4): 2 numbers, too few for its properties");
  EXPECT_EQ(error_of("bad-line.ply", "ply\nformat ascii 1.0\nelement face 5\x02ply\nend_header\n"),
            "line 3 of its PLY header is 'element face 5?ply': expected 'element', a name and a "
            "count");
}

// Found by fuzzing (docs/fuzzing.md): Debian's assimp 5.2 allocates what a binary glTF's chunk
// length says before reading it (3.5 GB for a damaged 10 kB file). The lengths are checked first.
TEST_F(SurfaceImportTest, ABinaryGltfChunkLongerThanItsFileIsRefused) {
  TriangleSurface tetrahedron;
  tetrahedron.vertices_m = {{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, 0.01}};
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const fs::path file = folder_ / "tetrahedron.glb";
  export_surface(tetrahedron, 1000.0, "glb2", file);
  EXPECT_EQ(read_surface_file(file, 1e-3).triangles.size(), 4u);
  std::string bytes;
  {
    std::ifstream in(file, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_GT(bytes.size(), 20u);
  bytes.replace(12, 4, std::string("\x8c\x04\x00\xd3", 4));  // chunk 1: 3 539 993 740 bytes
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  try {
    read_surface_file(file, 1e-3);
    ADD_FAILURE() << "a chunk longer than its file was read";
  } catch (const SurfaceImportError& e) {
    EXPECT_EQ(std::string(e.what()),
              file.string() +
                  ": cannot read it as a surface model: its binary glTF chunk 1 gives a length of "
                  "3539993740 bytes, more than the " +
                  std::to_string(bytes.size() - 20) + " left in the file");
  }
}

// Found by fuzzing (docs/fuzzing.md): damaged files that crash Debian's assimp 5.2 inside its
// readers (here its glTF 2 reader dereferences a null pointer). The model is read in a child
// process, so that such a file is an error naming it, and the program goes on.
TEST_F(SurfaceImportTest, AModelThatCrashesAssimpIsAnErrorNotACrash) {
  // The fuzzer's input: its first byte picked the format (.glb), the file follows.
  const fs::path input = fs::path(LIVERSIM_TEST_DATA_DIR) / ".." / "fuzz" / "regressions" /
                         "surface_import" / "glb-crashes-assimp-found.glb";
  std::ifstream in(input, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_GT(bytes.size(), 1u) << input;
  const fs::path file = folder_ / "crashes-assimp.glb";
  std::ofstream(file, std::ios::binary) << bytes.substr(1);
  try {
    read_surface_file(file, 1e-3);
    ADD_FAILURE() << "the damaged file was read";
  } catch (const SurfaceImportError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() +
                                         ": cannot read it as a surface model: its reader "
                                         "(assimp) crashed (Segmentation fault) on it (a damaged "
                                         "file?)");
  }
  // And the next model reads as ever.
  const fs::path cube = fs::path(LIVERSIM_TEST_DATA_DIR) / "cube-40mm.obj";
  EXPECT_EQ(read_surface_file(cube, 1e-3).triangles.size(), 192u);
}

// Found by fuzzing (docs/fuzzing.md), in the reading in a child process: a model whose triangles
// all fall away (its vertices not numbers, welded into one) came back as no triangles, copied from
// a null pointer. It is the error it always was.
TEST_F(SurfaceImportTest, AModelWithNoTrianglesLeftIsAnError) {
  const fs::path file = folder_ / "no-numbers.obj";
  std::ofstream(file) << "v 0 0 0\nv nan 0 0\nv 0 nan 0\nf 1 2 3\nv 0 0 0\n";
  try {
    read_surface_file(file, 1e-3);
    ADD_FAILURE() << "a model without triangles was read";
  } catch (const SurfaceImportError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": the file holds no triangles");
  }
}

// A scenario with a surface model: written and read back equal, and built at its element count
// with a lesion and a fixed ball like any organ; a bad unit, format or field named by its path.
TEST_F(SurfaceImportTest, AScenarioRunsAnImportedSurfaceModel) {
  const TriangleSurface liver = liver_surface();
  export_surface(liver, 100.0, "stlb", folder_ / "liver.stl");  // in centimetres
  ScenarioReading shipped =
      read_scenario_file(fs::path(LIVERSIM_TEST_DATA_DIR) / "scenario-small-resection.json");
  ASSERT_TRUE(shipped.scenario);
  Scenario s = *shipped.scenario;
  s.organ = OrganSpec{};
  s.organ.geometry = OrganGeometry::surface_file;
  s.organ.file = "liver.stl";
  s.organ.metres_per_unit = 1e-2;
  s.organ.target_tet_count = 2500;
  // A lesion at the liver's centroid, a ball held at its first vertex.
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : liver.vertices_m) centroid_m += v;
  centroid_m /= static_cast<double>(liver.vertices_m.size());
  ASSERT_FALSE(s.lesions.empty());
  s.lesions.resize(1);
  for (int k = 0; k < 3; ++k) s.lesions[0].centre_mm[k] = centroid_m[k] * 1e3;
  s.organ.fixed_balls.push_back({{liver.vertices_m[0].x() * 1e3, liver.vertices_m[0].y() * 1e3,
                                  liver.vertices_m[0].z() * 1e3},
                                 10.0});
  ASSERT_TRUE(validate(s).empty()) << validate(s).front().text();

  const ScenarioReading again = read_scenario(write_scenario(s));
  ASSERT_TRUE(again.scenario) << again.errors.front().text();
  EXPECT_EQ(*again.scenario, s);

  int reports = 0;
  const SceneSetup scene = build_scene(s, folder_, [&](const MeshingProgress&) {
    ++reports;
    return true;
  });
  EXPECT_GE(reports, 2);
  EXPECT_NEAR(static_cast<double>(scene.mesh.tet_count()), 2500.0, 0.05 * 2500.0);
  EXPECT_GT(std::count(scene.mesh.region.begin(), scene.mesh.region.end(), 1), 0)
      << "no element in the lesion";
  EXPECT_FALSE(scene.model_options.fixed_nodes.empty()) << "the ball holds nothing";

  auto errors_of = [](const std::string& organ) {
    std::string text =
        R"({"format": "liversim-scenario", "version": 1, "title": "t", "organ": )" + organ + "}";
    std::string all;
    for (const ScenarioError& e : read_scenario(text).errors) all += e.text() + "\n";
    return all;
  };
  EXPECT_NE(errors_of(R"({"geometry": "surface-file", "file": "a.stl", "length_unit": "inch"})")
                .find("organ.length_unit: is \"inch\"; expected mm, cm or m"),
            std::string::npos);
  EXPECT_NE(errors_of(R"({"geometry": "surface-file", "file": "a.stl"})").find("organ.length_unit"),
            std::string::npos);
  Scenario text_file = s;
  text_file.organ.file = "a.txt";
  const auto file_errors = validate(text_file);
  ASSERT_FALSE(file_errors.empty());
  EXPECT_NE(file_errors.front().text().find(
                "organ.file: \"a.txt\" is invalid: expected a surface model (.obj"),
            std::string::npos)
      << file_errors.front().text();
  EXPECT_NE(errors_of(R"({"geometry": "built-in-liver", "length_unit": "mm"})")
                .find("organ.length_unit: is for geometry surface-file only"),
            std::string::npos);
  // A surface that bounds no solid is named with its file when the scene is built.
  TriangleSurface holed = liver;
  holed.triangles.pop_back();
  export_surface(holed, 100.0, "stlb", folder_ / "holed.stl");
  s.organ.file = "holed.stl";
  try {
    build_scene(s, folder_);
    ADD_FAILURE() << "a surface with a hole was built";
  } catch (const SurfaceImportError& e) {
    EXPECT_NE(std::string(e.what()).find("holed.stl"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace liversim

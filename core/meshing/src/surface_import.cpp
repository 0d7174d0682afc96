#include "liversim/meshing/surface_import.h"

#include "liversim/engine/surface.h"
#include "liversim/engine/surface_bvh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gmsh.h>
#include "assimp_reading.h"

#include <assimp/Importer.hpp>

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <unordered_map>

#if defined(__SANITIZE_ADDRESS__)  // GCC; clang says so by __has_feature
#define LIVERSIM_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LIVERSIM_ADDRESS_SANITIZER 1
#endif
#endif
#if defined(LIVERSIM_ADDRESS_SANITIZER)
#include <sanitizer/common_interface_defs.h>
#endif

namespace liversim {
namespace {

std::string where_mm(const Eigen::Vector3d& point_m) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(1);
  text << "(" << point_m.x() * 1e3 << ", " << point_m.y() * 1e3 << ", " << point_m.z() * 1e3
       << ") mm";
  return text.str();
}

// Whether segment [p, q] crosses triangle (a, b, c) at an interior point of both (Möller–Trumbore;
// touching at an edge or a corner does not count).
bool segment_crosses_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                              const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  const double scale = d.norm() * e1.norm() * e2.norm();
  if (std::abs(det) <= 1e-12 * scale) return false;  // parallel or coplanar: not counted
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) / det;
  const Eigen::Vector3d k = s.cross(e1);
  const double v = d.dot(k) / det;
  const double t = e2.dot(k) / det;
  constexpr double kInside = 1e-9;
  return u > kInside && v > kInside && u + v < 1.0 - kInside && t > kInside && t < 1.0 - kInside;
}

bool triangles_cross(const std::array<Eigen::Vector3d, 3>& a,
                     const std::array<Eigen::Vector3d, 3>& b) {
  for (int i = 0; i < 3; ++i) {
    if (segment_crosses_triangle(a[i], a[(i + 1) % 3], b[0], b[1], b[2])) return true;
    if (segment_crosses_triangle(b[i], b[(i + 1) % 3], a[0], a[1], a[2])) return true;
  }
  return false;
}

// Gmsh has one global state: one user at a time, initialised and finalised around each use.
std::mutex gmsh_mutex;

struct GmshSession {
  GmshSession() {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.NumThreads", 1);
  }
  ~GmshSession() {
    try {
      gmsh::finalize();
    } catch (...) {  // Gmsh throws its last error again (a std::string) on any later call
    }
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

int count_tets() {
  std::vector<std::size_t> tags, nodes;
  gmsh::model::mesh::getElementsByType(4, tags, nodes);
  return static_cast<int>(tags.size());
}

TetMesh read_gmsh_model() {
  std::vector<std::size_t> node_tags;
  std::vector<double> coord, parametric;
  gmsh::model::mesh::getNodes(node_tags, coord, parametric, -1, -1, true, false);
  std::vector<std::size_t> tet_tags, tet_nodes;
  gmsh::model::mesh::getElementsByType(4, tet_tags, tet_nodes);
  // Only the nodes of elements, numbered in the order the elements meet them.
  std::unordered_map<std::size_t, std::size_t> position_of;
  for (std::size_t i = 0; i < node_tags.size(); ++i) position_of[node_tags[i]] = i;
  std::unordered_map<std::size_t, NodeIndex> index_of;
  TetMesh mesh;
  auto node = [&](std::size_t tag) {
    const auto [it, added] = index_of.try_emplace(tag, static_cast<NodeIndex>(index_of.size()));
    if (added) {
      const std::size_t i = position_of.at(tag);
      mesh.rest_position_m.push_back({coord[3 * i], coord[3 * i + 1], coord[3 * i + 2]});
    }
    return it->second;
  };
  for (std::size_t e = 0; e < tet_tags.size(); ++e) {
    std::array<NodeIndex, 4> corners;
    for (int c = 0; c < 4; ++c) corners[c] = node(tet_nodes[4 * e + c]);
    const double volume =
        signed_tet_volume(mesh.rest_position_m.at(corners[0]), mesh.rest_position_m.at(corners[1]),
                          mesh.rest_position_m.at(corners[2]), mesh.rest_position_m.at(corners[3]));
    if (volume < 0.0) std::swap(corners[2], corners[3]);
    mesh.add_tet(corners);
  }
  return mesh;
}

TetMesh mesh_with_gmsh(const TriangleSurface& surface, const SurfaceMeshingOptions& options) {
  const double volume_m3 = std::abs(surface.volume_m3());
  gmsh::model::add("organ");
  const int discrete = gmsh::model::addDiscreteEntity(2);
  std::vector<std::size_t> node_tags(surface.vertices_m.size());
  std::vector<double> coord;
  coord.reserve(3 * surface.vertices_m.size());
  for (std::size_t i = 0; i < surface.vertices_m.size(); ++i) {
    node_tags[i] = i + 1;
    for (int k = 0; k < 3; ++k) coord.push_back(surface.vertices_m[i][k]);
  }
  gmsh::model::mesh::addNodes(2, discrete, node_tags, coord);
  std::vector<std::size_t> triangle_nodes;
  triangle_nodes.reserve(3 * surface.triangles.size());
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) triangle_nodes.push_back(static_cast<std::size_t>(t[k]) + 1);
  gmsh::model::mesh::addElementsByType(discrete, 2, {}, triangle_nodes);
  // The surface's own triangles bound the volume (Gmsh would remesh it only after splitting it
  // into patches it can parametrise, which fails on coarse organ models); the interior is
  // meshed at the element size.
  const int loop = gmsh::model::geo::addSurfaceLoop({discrete});
  const int volume = gmsh::model::geo::addVolume({loop});
  gmsh::model::geo::synchronize();
  gmsh::option::setNumber("Mesh.Optimize",
                          1);  // Gmsh's own: fewer flat elements, a longer stable step

  // First guess: V/h³ regular tetrahedra of edge h fill 6√2 ≈ 8.5 per h³; each next attempt
  // scales h by the cube root of the miss.
  double size_m = std::cbrt(8.5 * volume_m3 / options.target_tet_count);
  int best_miss = -1;
  double best_size_m = size_m;
  for (int attempt = 1; attempt <= options.max_attempts; ++attempt) {
    MeshingProgress progress{attempt, options.max_attempts, size_m * 1e3, 0};
    if (options.progress && !options.progress(progress)) throw SurfaceMeshingCancelled();
    gmsh::option::setNumber("Mesh.MeshSizeMin", size_m);
    gmsh::option::setNumber("Mesh.MeshSizeMax", size_m);
    gmsh::model::mesh::clear({{3, volume}});  // the surface's triangles stay
    gmsh::model::mesh::generate(3);
    progress.tet_count = count_tets();
    if (options.progress && !options.progress(progress)) throw SurfaceMeshingCancelled();
    if (progress.tet_count == 0) throw SurfaceImportError("Gmsh made no elements of the solid");
    const int miss = std::abs(progress.tet_count - options.target_tet_count);
    if (best_miss < 0 || miss < best_miss) {
      best_miss = miss;
      best_size_m = size_m;
    }
    if (miss <= options.count_tolerance * options.target_tet_count) return read_gmsh_model();
    size_m *= std::cbrt(static_cast<double>(progress.tet_count) / options.target_tet_count);
  }
  // None within the tolerance: the closest.
  gmsh::option::setNumber("Mesh.MeshSizeMin", best_size_m);
  gmsh::option::setNumber("Mesh.MeshSizeMax", best_size_m);
  gmsh::model::mesh::clear({{3, volume}});  // the surface's triangles stay
  gmsh::model::mesh::generate(3);
  return read_gmsh_model();
}

}  // namespace

double TriangleSurface::volume_m3() const {
  double six_volume = 0.0;
  for (const auto& t : triangles)
    six_volume += vertices_m[t[0]].dot(vertices_m[t[1]].cross(vertices_m[t[2]]));
  return six_volume / 6.0;
}

const std::vector<std::string>& surface_file_extensions() {
  static const std::vector<std::string> extensions = {".obj", ".stl", ".ply", ".gltf",
                                                      ".glb", ".fbx", ".3ds"};
  return extensions;
}

bool is_surface_file(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const auto& known = surface_file_extensions();
  return std::find(known.begin(), known.end(), extension) != known.end();
}

namespace {

// The triangles of the file, read here, in this process.
TriangleSurface read_surface_here(const std::filesystem::path& file, double metres_per_unit) {
  Assimp::Importer importer;
  const aiScene* scene = detail::read_assimp_scene(
      importer, file, metres_per_unit,
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
          aiProcess_SortByPType | aiProcess_FindDegenerates,
      "a surface model");
  TriangleSurface surface;
  // The same point in two meshes (or twice in one) is one vertex.
  std::map<std::array<double, 3>, std::int32_t> vertex_at;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    std::vector<std::int32_t> index(mesh->mNumVertices);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const std::array<double, 3> key{p.x * metres_per_unit, p.y * metres_per_unit,
                                      p.z * metres_per_unit};
      const auto [it, added] =
          vertex_at.try_emplace(key, static_cast<std::int32_t>(surface.vertices_m.size()));
      if (added) surface.vertices_m.emplace_back(key[0], key[1], key[2]);
      index[v] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      const std::array<std::int32_t, 3> t{index[face.mIndices[0]], index[face.mIndices[1]],
                                          index[face.mIndices[2]]};
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;  // welded to nothing
      surface.triangles.push_back(t);
    }
  }
  return surface;
}

// The reader's answer on the pipe: 'S', then the vertex count (u64), the vertices (3 doubles
// each), the triangle count (u64) and the triangles (3 int32 each); or 'E' and a message.
bool write_all(int fd, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, bytes, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

[[noreturn]] void answer_and_exit(int fd, const std::filesystem::path& file,
                                  double metres_per_unit) {
  std::string message;
  try {
    const TriangleSurface surface = read_surface_here(file, metres_per_unit);
    const std::uint64_t vertices = surface.vertices_m.size(), triangles = surface.triangles.size();
    bool ok = write_all(fd, "S", 1) && write_all(fd, &vertices, sizeof vertices);
    for (const Eigen::Vector3d& v : surface.vertices_m)
      ok = ok && write_all(fd, v.data(), 3 * sizeof(double));
    ok = ok && write_all(fd, &triangles, sizeof triangles) &&
         write_all(fd, surface.triangles.data(), triangles * sizeof surface.triangles[0]);
    ::_exit(ok ? 0 : 3);
  } catch (const std::exception& e) {
    message = e.what();
  } catch (...) {
    message = file.string() + ": cannot read it as a surface model";
  }
  write_all(fd, "E", 1);
  write_all(fd, message.data(), message.size());
  ::_exit(0);
}

// The reader child: this program run again with these variables set. It reads before main (below)
// and exits, whichever program it is (the workstation, the CLI, a test).
constexpr int kReaderAnswerFd = 3;
constexpr const char* kReaderFileVariable = "LIVERSIM_SURFACE_READER_FILE";
constexpr const char* kReaderUnitVariable = "LIVERSIM_SURFACE_READER_METRES_PER_UNIT";

struct ReaderCommand {
  ReaderCommand(const std::filesystem::path& file, double metres_per_unit) {
    char unit[64];
    std::snprintf(unit, sizeof unit, "%.17g", metres_per_unit);
    strings.push_back(std::string(kReaderFileVariable) + "=" + file.string());
    strings.push_back(std::string(kReaderUnitVariable) + "=" + unit);
    for (char** variable = environ; *variable != nullptr; ++variable)
      if (std::strncmp(*variable, "LIVERSIM_SURFACE_READER_", 24) != 0)
        strings.emplace_back(*variable);
    for (std::string& s : strings) environment.push_back(s.data());
    environment.push_back(nullptr);
  }
  std::vector<std::string> strings;
  std::vector<char*> environment;
  std::array<char*, 2> argv{const_cast<char*>("liversim-surface-reader"), nullptr};
};

[[gnu::constructor]] void run_as_surface_reader() {
  const char* file = std::getenv(kReaderFileVariable);
  const char* unit = std::getenv(kReaderUnitVariable);
  if (file == nullptr || unit == nullptr) return;
  // Dying of its own faults rather than reporting them: a crash is the parent's answer.
  for (int signal : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT}) std::signal(signal, SIG_DFL);
#if defined(LIVERSIM_ADDRESS_SANITIZER)
  __sanitizer_set_death_callback(nullptr);
#endif
  answer_and_exit(kReaderAnswerFd, file, std::strtod(unit, nullptr));
}

}  // namespace

// Read in a child process: Debian's assimp 5.2 crashes, corrupts its heap, hangs or allocates
// without bound on damaged files in several of its readers (fuzzing found it in the PLY and glTF
// ones, docs/fuzzing.md). A child that dies or overruns its time is an error of the file; the
// workstation goes on. The checks that need no assimp run here first, with their own messages.
// The child runs this program again (exec) rather than reading in the forked copy: the GUI calling
// this has other threads, and a lock one of them held at the fork (AddressSanitizer's allocator
// did, docs/sanitizers.md) would leave the copy hanging on a sound file.
TriangleSurface read_surface_file(const std::filesystem::path& file, double metres_per_unit) {
  const std::string name = file.string();
  if (!(metres_per_unit > 0.0) || !std::isfinite(metres_per_unit))
    throw SurfaceImportError(name + ": the length unit must be a positive number of metres");
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw SurfaceImportError(name + ": no such file");
  const auto refused = [&](const std::string& why) {
    return SurfaceImportError(name + ": cannot read it as a surface model: " + why);
  };
  if (auto problem = detail::ply_problem(file); problem || (problem = detail::glb_problem(file)))
    throw refused(*problem);
  // Time enough for any sound model: assimp reads tens of megabytes a second.
  const auto bytes = std::filesystem::file_size(file, ec);
  const auto allowed = std::chrono::seconds(5) + std::chrono::milliseconds(ec ? 0 : bytes / 500);
  const auto deadline = std::chrono::steady_clock::now() + allowed;

  const ReaderCommand reader(file, metres_per_unit);  // made before the fork: it allocates
  int channel[2];
  if (::pipe2(channel, O_CLOEXEC) != 0)
    throw refused(std::string("cannot start its reader: ") + std::strerror(errno));
  const pid_t child = ::fork();
  if (child < 0) {
    const int error = errno;
    ::close(channel[0]);
    ::close(channel[1]);
    throw refused(std::string("cannot start its reader: ") + std::strerror(error));
  }
  if (child == 0) {  // async-signal-safe calls only until exec
    ::close(channel[0]);
    // The answer goes to descriptor 3, which stays open across exec; stderr to /dev/null.
    if (channel[1] == kReaderAnswerFd)
      ::fcntl(kReaderAnswerFd, F_SETFD, 0);
    else
      ::dup2(channel[1], kReaderAnswerFd);
    if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, STDERR_FILENO);
    ::execve("/proc/self/exe", reader.argv.data(), reader.environment.data());
    ::_exit(127);
  }
  ::close(channel[1]);
  std::string answer;
  bool overran = false;
  for (std::array<char, 1 << 16> buffer;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    pollfd ready{channel[0], POLLIN, 0};
    const int polled = ::poll(&ready, 1, static_cast<int>(std::max<long long>(0, left.count())));
    if (polled < 0 && errno == EINTR) continue;
    if (polled == 0) {
      overran = true;
      break;
    }
    const ssize_t n = ::read(channel[0], buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    answer.append(buffer.data(), static_cast<std::size_t>(n));
  }
  ::close(channel[0]);
  if (overran) ::kill(child, SIGKILL);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (overran)
    throw refused(
        "its reader (assimp) took longer than " +
        std::to_string(std::chrono::duration_cast<std::chrono::seconds>(allowed).count()) +
        " s and was stopped (a damaged file?)");
  if (!answer.empty() && answer[0] == 'E') throw SurfaceImportError(answer.substr(1));

  TriangleSurface surface;
  std::size_t at = 1;
  const auto take = [&](void* out, std::size_t size) {
    if (answer.size() - at < size) return false;
    if (size > 0) std::memcpy(out, answer.data() + at, size);  // no triangles: `out` is null
    at += size;
    return true;
  };
  std::uint64_t vertices = 0, triangles = 0;
  bool whole = !answer.empty() && answer[0] == 'S' && take(&vertices, sizeof vertices) &&
               vertices <= answer.size() / (3 * sizeof(double));
  if (whole) {
    surface.vertices_m.resize(vertices);
    for (Eigen::Vector3d& v : surface.vertices_m)
      whole = whole && take(v.data(), 3 * sizeof(double));
    whole = whole && take(&triangles, sizeof triangles) &&
            triangles <= answer.size() / sizeof surface.triangles[0];
  }
  if (whole) {
    surface.triangles.resize(triangles);
    whole = take(surface.triangles.data(), triangles * sizeof surface.triangles[0]) &&
            at == answer.size();
  }
  if (!whole) {
    const std::string how = WIFSIGNALED(status)
                                ? std::string("crashed (") + ::strsignal(WTERMSIG(status)) + ")"
                                : "stopped without an answer";
    throw refused("its reader (assimp) " + how + " on it (a damaged file?)");
  }
  if (surface.triangles.empty()) throw SurfaceImportError(name + ": the file holds no triangles");
  for (const Eigen::Vector3d& v : surface.vertices_m)
    if (!v.allFinite()) throw SurfaceImportError(name + ": a vertex is not a number");
  return surface;
}

std::vector<std::string> surface_problems(const TriangleSurface& surface, int max_problems) {
  std::vector<std::string> problems;
  int more = 0;
  auto report = [&](std::string text) {
    if (static_cast<int>(problems.size()) < max_problems)
      problems.push_back(std::move(text));
    else
      ++more;
  };
  const auto& v = surface.vertices_m;
  auto centre = [&](std::size_t t) {
    const auto& tri = surface.triangles[t];
    return Eigen::Vector3d((v[tri[0]] + v[tri[1]] + v[tri[2]]) / 3.0);
  };
  // Edges: each must be used twice, once in each direction.
  std::map<std::pair<std::int32_t, std::int32_t>, std::pair<int, int>> edge_uses;  // (fwd, back)
  for (const auto& t : surface.triangles)
    for (int i = 0; i < 3; ++i) {
      const std::int32_t a = t[i], b = t[(i + 1) % 3];
      auto& uses = edge_uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? uses.first : uses.second) += 1;
    }
  int open = 0, non_manifold = 0, flipped = 0;
  for (const auto& [edge, uses] : edge_uses) {
    const Eigen::Vector3d middle = (v[edge.first] + v[edge.second]) / 2.0;
    const int total = uses.first + uses.second;
    if (total == 1) {
      if (open++ == 0) report("the surface is not closed: a hole's edge at " + where_mm(middle));
    } else if (total > 2) {
      if (non_manifold++ == 0)
        report("an edge at " + where_mm(middle) + " belongs to " + std::to_string(total) +
               " triangles (a surface can only meet itself along an edge once)");
    } else if (uses.first != 1) {
      if (flipped++ == 0)
        report("triangles face against their neighbour at the edge at " + where_mm(middle) +
               " (inconsistent orientation)");
    }
  }
  if (open > 1) report(std::to_string(open) + " edges border holes in all");
  if (non_manifold > 1) report(std::to_string(non_manifold) + " edges are shared by 3 or more");
  if (flipped > 1) report(std::to_string(flipped) + " edges join triangles facing apart");
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    const double area2 = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]).norm();
    const double longest = std::max({(v[tri[1]] - v[tri[0]]).norm(), (v[tri[2]] - v[tri[1]]).norm(),
                                     (v[tri[0]] - v[tri[2]]).norm()});
    if (area2 <= 1e-12 * longest * longest) {
      report("a triangle at " + where_mm(centre(t)) + " has no area");
      break;
    }
  }
  // Crossings, between triangles that share no vertex.
  BoundarySurface boundary;
  boundary.nodes.resize(v.size());
  NodeArray position;
  for (std::size_t i = 0; i < v.size(); ++i) {
    boundary.nodes[i] = static_cast<NodeIndex>(i);
    position.push_back(v[i]);
  }
  boundary.triangles = surface.triangles;
  const SurfaceBvh bvh(boundary, position);
  int crossings = 0;
  for (std::size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& a = surface.triangles[t];
    Aabb box;
    for (int i = 0; i < 3; ++i) box.grow(v[a[i]]);
    const std::array<Eigen::Vector3d, 3> ta{v[a[0]], v[a[1]], v[a[2]]};
    bvh.for_each_triangle_overlapping(box, [&](std::int32_t u) {
      if (static_cast<std::size_t>(u) <= t) return;  // each pair once
      const auto& b = surface.triangles[u];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (a[i] == b[j]) return;
      if (triangles_cross(ta, {v[b[0]], v[b[1]], v[b[2]]}))
        if (crossings++ == 0)
          report("the surface intersects itself: triangles at " + where_mm(centre(t)) + " and " +
                 where_mm(centre(static_cast<std::size_t>(u))) + " cross");
    });
  }
  if (crossings > 1) report(std::to_string(crossings) + " pairs of triangles cross in all");
  if (more > 0) problems.push_back("and " + std::to_string(more) + " more problems");
  return problems;
}

void orient_outward(TriangleSurface& surface) {
  if (surface.volume_m3() >= 0.0) return;
  for (auto& t : surface.triangles) std::swap(t[1], t[2]);
}

TetMesh tetrahedralise_surface(const TriangleSurface& surface,
                               const SurfaceMeshingOptions& options) {
  if (options.target_tet_count < 4 || options.max_attempts < 1 || !(options.count_tolerance > 0))
    throw std::invalid_argument("tetrahedralise_surface: bad options");
  if (const auto problems = surface_problems(surface); !problems.empty()) {
    std::string text = "the surface bounds no solid:";
    for (const std::string& problem : problems) text += "\n  " + problem;
    throw SurfaceImportError(text);
  }
  std::lock_guard lock(gmsh_mutex);
  GmshSession session;
  try {
    return mesh_with_gmsh(surface, options);
  } catch (const std::string& error) {  // how Gmsh's API reports an error
    throw SurfaceImportError("Gmsh could not mesh the solid: " + error);
  }
}

}  // namespace liversim

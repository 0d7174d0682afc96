#include "assimp_reading.h"

#include <assimp/postprocess.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <set>
#include <string_view>
#include <vector>

namespace liversim::detail {

namespace {

// assimp's triangulation and search for degenerate faces take time growing with the square of a
// face's corners: a damaged PLY of 1.7 kB, read as a face of 293 840 corners, took 100 s (found
// by fuzzing, docs/fuzzing.md).
constexpr unsigned kMaxFaceCorners = 4096;

// A PLY scalar type.
struct PlyType {
  std::size_t bytes = 0;
  bool is_signed = false, is_integer = false;
  std::uint64_t max() const {  // the largest count an integer type holds
    return bytes >= 8 ? UINT64_MAX : (std::uint64_t{1} << (8 * bytes - (is_signed ? 1 : 0))) - 1;
  }
};

std::optional<PlyType> ply_type(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, PlyType>, 16> kTypes = {{
      {"char", {1, true, true}},
      {"int8", {1, true, true}},
      {"uchar", {1, false, true}},
      {"uint8", {1, false, true}},
      {"short", {2, true, true}},
      {"int16", {2, true, true}},
      {"ushort", {2, false, true}},
      {"uint16", {2, false, true}},
      {"int", {4, true, true}},
      {"int32", {4, true, true}},
      {"uint", {4, false, true}},
      {"uint32", {4, false, true}},
      {"float", {4, true, false}},
      {"float32", {4, true, false}},
      {"double", {8, true, false}},
      {"float64", {8, true, false}},
  }};
  for (const auto& [type_name, type] : kTypes)
    if (type_name == name) return type;
  return std::nullopt;
}

struct PlyProperty {
  std::string name;
  PlyType type;                  // of the value, or of a list's items
  std::optional<PlyType> count;  // a list's count
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::string instance(std::uint64_t i) const {  // "face 12 of 192", counted from 1
    return name + " " + std::to_string(i + 1) + " of " + std::to_string(count);
  }
};

enum class PlyFormat { unknown, ascii, binary_little_endian, binary_big_endian };

std::vector<std::string_view> words_of(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t at = 0;
  while ((at = line.find_first_not_of(" \t\r", at)) != std::string_view::npos) {
    const auto end = std::min(line.find_first_of(" \t\r", at), line.size());
    words.push_back(line.substr(at, end - at));
    at = end;
  }
  return words;
}

std::string shown(std::string_view text) {
  std::string out;
  for (char c : text.substr(0, 40)) out += (c >= 32 && c < 127) ? c : '?';
  return "'" + out + (text.size() > 40 ? "...'" : "'");
}

template <typename Number>
bool parse_whole(std::string_view word, Number& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc() && end == word.data() + word.size();
}

// Lines of a text, with their numbers from 1.
class Lines {
 public:
  Lines(std::string_view text, std::size_t from, int number)
      : text_(text), at_(from), number_(number) {}
  bool next(std::string_view& line) {
    if (at_ >= text_.size()) return false;
    const auto end = std::min(text_.find('\n', at_), text_.size());
    line = text_.substr(at_, end - at_);
    at_ = end + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }                              // of the line read last
  std::size_t offset() const { return std::min(at_, text_.size()); }  // after it

 private:
  std::string_view text_;
  std::size_t at_;
  int number_;
};

// The data of an ASCII PLY: one instance a line, each property a number, each list its count (in
// its type's range) and as many numbers.
std::optional<std::string> ascii_ply_data_problem(const std::vector<PlyElement>& elements,
                                                  Lines lines) {
  std::string_view line;
  for (const PlyElement& e : elements)
    for (std::uint64_t i = 0; i < e.count; ++i) {
      std::vector<std::string_view> w;
      do {
        if (!lines.next(line)) return "its PLY data ends before " + e.instance(i);
        w = words_of(line);
      } while (w.empty());
      const auto at = [&] {  // spelled out only for a message
        return "line " + std::to_string(lines.number()) + " (" + e.instance(i) + ")";
      };
      std::size_t k = 0;
      for (const PlyProperty& p : e.properties) {
        std::uint64_t items = 1;
        if (p.count) {
          if (k >= w.size() || !parse_whole(w[k], items) || items > p.count->max())
            return at() + ": the count of its list '" + p.name + "' is " +
                   (k < w.size() ? shown(w[k]) : std::string("missing")) + ", expected 0 to " +
                   std::to_string(p.count->max());
          ++k;
        }
        if (items > w.size() - k)
          return at() + ": " + std::to_string(w.size()) + " numbers, too few for its properties";
        for (std::uint64_t n = 0; n < items; ++n, ++k) {
          double value = 0.0;
          if (!parse_whole(w[k], value))
            return at() + ": " + shown(w[k]) + " for '" + p.name + "' is no number";
        }
      }
    }
  return std::nullopt;
}

// The data of a binary PLY: every instance whole, each list's count in range.
std::optional<std::string> binary_ply_data_problem(const std::vector<PlyElement>& elements,
                                                   std::string_view data, bool big_endian) {
  std::size_t at = 0;
  for (const PlyElement& e : elements)
    for (std::uint64_t i = 0; i < e.count; ++i)
      for (const PlyProperty& p : e.properties) {
        std::uint64_t items = 1;
        if (p.count) {
          const std::size_t n = p.count->bytes;
          if (data.size() - at < n) return "its PLY data ends inside " + e.instance(i);
          std::uint64_t raw = 0;
          for (std::size_t b = 0; b < n; ++b) {
            const auto byte = static_cast<unsigned char>(data[at + (big_endian ? b : n - 1 - b)]);
            raw = (raw << 8) | byte;
          }
          at += n;
          if (p.count->is_signed && (raw >> (8 * n - 1)) != 0)
            return e.instance(i) + " of its PLY data has a negative count for its list '" + p.name +
                   "'";
          items = raw;
        }
        if (items > (data.size() - at) / p.type.bytes)
          return "its PLY data ends inside " + e.instance(i);
        at += items * p.type.bytes;
      }
  return std::nullopt;
}

}  // namespace

// Debian's assimp 5.2 reads a PLY header that never ends forever, corrupts its heap on an element
// declared twice, reads forever or allocates without bound for a count the file cannot hold, and
// allocates gigabytes for a list count the data damaged (each found by fuzzing, docs/fuzzing.md).
// A PLY file is small to check: its header line by line, then its data against the header.
std::optional<std::string> ply_problem(const std::filesystem::path& file) {
  // assimp reads a file as PLY by its extension, or by "ply" (in any case) after blanks at its
  // start.
  std::ifstream in(file, std::ios::binary);
  std::string start(64, '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  start.resize(static_cast<std::size_t>(in.gcount()));
  const auto first = start.find_first_not_of(" \t\r\n");
  const bool looks_like_ply =
      first != std::string::npos && start.size() - first >= 3 &&
      std::equal(start.begin() + first, start.begin() + first + 3, "ply",
                 [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!looks_like_ply && extension != ".ply") return std::nullopt;
  in.clear();
  in.seekg(0);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};

  PlyFormat format = PlyFormat::unknown;
  std::vector<PlyElement> elements;
  std::set<std::string, std::less<>> element_names;
  Lines lines(text, 0, 0);
  for (std::string_view line;;) {
    if (!lines.next(line)) return "its PLY header has no end_header line (a cut-short file?)";
    const std::string at = "line " + std::to_string(lines.number()) + " of its PLY header ";
    if (line.find('\0') != std::string_view::npos) return at + "holds a NUL byte";
    const std::vector<std::string_view> w = words_of(line);
    if (lines.number() == 1) {
      if (w.size() != 1 || w[0].size() != 3 || !looks_like_ply || first != 0)
        return at + "is " + shown(line) + ", not 'ply' (the first line of a PLY file)";
      continue;
    }
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (format != PlyFormat::unknown) return at + "gives the format a second time";
      if (w.size() == 3 && w[1] == "ascii") format = PlyFormat::ascii;
      if (w.size() == 3 && w[1] == "binary_little_endian") format = PlyFormat::binary_little_endian;
      if (w.size() == 3 && w[1] == "binary_big_endian") format = PlyFormat::binary_big_endian;
      if (format == PlyFormat::unknown)
        return at + "is " + shown(line) +
               ": expected 'format' and ascii, binary_little_endian or binary_big_endian with "
               "a version";
    } else if (w[0] == "element") {
      std::uint64_t count = 0;
      if (w.size() != 3 || !parse_whole(w[2], count))
        return at + "is " + shown(line) + ": expected 'element', a name and a count";
      if (!element_names.emplace(w[1]).second)
        return at + "declares the element " + shown(w[1]) + " a second time";
      elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (elements.empty()) return at + "gives a property before any element";
      const bool list = w.size() == 5 && w[1] == "list";
      const auto type =
          w.size() == 3 || list ? ply_type(w.size() == 3 ? w[1] : w[3]) : std::nullopt;
      const auto count = list ? ply_type(w[2]) : std::nullopt;
      if (!type || (list && (!count || !count->is_integer)))
        return at + "is " + shown(line) +
               ": expected 'property', a type and a name, or 'property list', an integer type, a "
               "type and a name";
      elements.back().properties.push_back({std::string(w.back()), *type, count});
    } else {
      return at + "is " + shown(line) + ", which no PLY header line is";
    }
  }
  if (format == PlyFormat::unknown) return "its PLY header gives no format line";

  // What the declared elements need at the least (in ASCII a number and a space or line end
  // each, the last one's end optional) must fit in what follows the header: checked first, so
  // that a count of billions is not walked through.
  const std::uint64_t after_header = text.size() - lines.offset();
  std::uint64_t left = after_header + (format == PlyFormat::ascii ? 1 : 0);
  for (const PlyElement& e : elements) {
    std::uint64_t least = 0;
    for (const PlyProperty& p : e.properties)
      least += format == PlyFormat::ascii ? 2 : (p.count ? p.count->bytes : p.type.bytes);
    least = std::max<std::uint64_t>(1, least);
    if (e.count > left / least)
      return "its PLY header declares " + std::to_string(e.count) + " of the element " +
             shown(e.name) + ", more than the " + std::to_string(after_header) +
             " bytes after the header hold (a damaged file?)";
    left -= e.count * least;
  }
  if (format == PlyFormat::ascii) return ascii_ply_data_problem(elements, lines);
  return binary_ply_data_problem(elements, std::string_view(text).substr(lines.offset()),
                                 format == PlyFormat::binary_big_endian);
}

// Debian's assimp 5.2 allocates what a binary glTF's chunk lengths say before reading them (3.5 GB
// for a damaged 10 kB file, found by fuzzing, docs/fuzzing.md): the lengths are checked against
// the file first.
std::optional<std::string> glb_problem(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::array<char, 4> magic{};
  in.read(magic.data(), magic.size());
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (std::string_view(magic.data(), magic.size()) != "glTF" && extension != ".glb")
    return std::nullopt;
  in.clear();
  in.seekg(0);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto u32 = [&](std::size_t at) {
    std::uint32_t value = 0;
    for (int b = 3; b >= 0; --b) value = (value << 8) | static_cast<unsigned char>(text[at + b]);
    return value;
  };
  if (text.size() < 12 || !text.starts_with("glTF"))
    return std::string("it does not start with a binary glTF header ('glTF', version, length)");
  const std::uint32_t version = u32(4), length = u32(8);
  if (length > text.size())
    return "its binary glTF header gives a length of " + std::to_string(length) +
           " bytes, but the file has " + std::to_string(text.size());
  if (version == 1) {  // glTF 1: the scene's length and format follow
    if (text.size() < 20 || u32(12) > length - 20)
      return "its binary glTF 1 header gives a scene longer than the file";
    return std::nullopt;
  }
  for (std::size_t at = 12, chunk = 1; at < length; ++chunk) {
    if (length - at < 8) return "its binary glTF chunk " + std::to_string(chunk) + " is cut short";
    const std::uint32_t chunk_length = u32(at);
    if (chunk_length > length - at - 8)
      return "its binary glTF chunk " + std::to_string(chunk) + " gives a length of " +
             std::to_string(chunk_length) + " bytes, more than the " +
             std::to_string(length - at - 8) + " left in the file";
    at += 8 + chunk_length;
  }
  return std::nullopt;
}

const aiScene* read_assimp_scene(Assimp::Importer& importer, const std::filesystem::path& file,
                                 double metres_per_unit, unsigned steps, const std::string& what) {
  const std::string name = file.string();
  if (!(metres_per_unit > 0.0) || !std::isfinite(metres_per_unit))
    throw SurfaceImportError(name + ": the length unit must be a positive number of metres");
  if (!std::filesystem::exists(file)) throw SurfaceImportError(name + ": no such file");
  const auto refused = [&](const std::string& why) {
    return SurfaceImportError(name + ": cannot read it as " + what + ": " + why);
  };
  if (auto problem = ply_problem(file); problem || (problem = glb_problem(file)))
    throw refused(*problem);
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(name, 0);
  if (scene == nullptr) throw refused(importer.GetErrorString());
  // Faces are checked before assimp's own steps see them: Debian's assimp 5.2 aborts in its
  // triangulation, and crashes sorting primitives, on a face of no corners (found by fuzzing,
  // docs/fuzzing.md); a corner past the vertices would be read out of bounds; a huge face takes
  // minutes.
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& mesh = *scene->mMeshes[m];
    const auto face_at = [&](unsigned f) {  // counted from 1, as a modelling package shows them
      return "face " + std::to_string(f + 1) + " of mesh " + std::to_string(m + 1);
    };
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 0) throw refused(face_at(f) + " has no corners");
      if (face.mNumIndices > kMaxFaceCorners)
        throw refused(face_at(f) + " has " + std::to_string(face.mNumIndices) +
                      " corners, more than the " + std::to_string(kMaxFaceCorners) +
                      " a model's face may have (a damaged file?)");
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh.mNumVertices)
          throw refused(face_at(f) + " has a corner at vertex " +
                        std::to_string(face.mIndices[k] + 1ull) + ", but the mesh has " +
                        std::to_string(mesh.mNumVertices) + " vertices");
    }
  }
  scene = importer.ApplyPostProcessing(steps);
  if (scene == nullptr) throw refused(importer.GetErrorString());
  return scene;
}

}  // namespace liversim::detail

#include "liversim/engine/mesh_io.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace liversim {

MeshReadError::MeshReadError(std::filesystem::path file, int line, const std::string& message)
    : std::runtime_error(file.string() + (line > 0 ? ":" + std::to_string(line) : std::string()) +
                         ": " + message),
      file_(std::move(file)),
      line_(line),
      message_(message) {}

namespace {

namespace fs = std::filesystem;
using Fields = std::vector<std::string_view>;

constexpr std::int64_t kMaxAbaqusId = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kMaxTag = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMaxInt32 = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kMinInt32 = std::numeric_limits<std::int32_t>::min();

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// Abaqus ignores blanks inside keyword and parameter names ("*End Part" == "*ENDPART").
std::string keyword_name(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != ' ' && c != '\t')
      out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// A short, printable excerpt of file content for an error message (the file may be binary).
std::string excerpt(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (char c : s.substr(0, kMax)) out += (c >= 32 && c < 127) ? c : '?';
  if (s.size() > kMax) out += "...";
  return out + "'";
}

void split_whitespace(std::string_view line, Fields& out) {
  out.clear();
  std::size_t pos = 0;
  while (true) {
    pos = line.find_first_not_of(" \t\r", pos);
    if (pos == std::string_view::npos) return;
    const auto end = std::min(line.find_first_of(" \t\r", pos), line.size());
    out.push_back(line.substr(pos, end - pos));
    pos = end;
  }
}

// Appends the comma-separated fields of an Abaqus line, trimmed. A trailing comma (which Abaqus
// allows, and uses to continue a line) does not add an empty field.
void append_comma_fields(std::string_view line, Fields& out) {
  if (!line.empty() && line.back() == ',') line.remove_suffix(1);
  std::size_t pos = 0;
  while (true) {
    const auto comma = line.find(',', pos);
    out.push_back(trim(line.substr(pos, comma == std::string_view::npos ? comma : comma - pos)));
    if (comma == std::string_view::npos) return;
    pos = comma + 1;
  }
}

std::string_view without_plus(std::string_view s) {
  return (s.size() > 1 && s[0] == '+' && s[1] != '+' && s[1] != '-') ? s.substr(1) : s;
}

// The whole field must be the number: "1.5abc" is not 1.5.
std::optional<double> parse_double(std::string_view s) {
  s = without_plus(s);
  if (s.empty()) return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (end != s.data() + s.size()) return std::nullopt;
  // from_chars leaves the value alone on overflow and underflow; strtod gives inf or 0.
  if (ec == std::errc::result_out_of_range) return std::strtod(std::string(s).c_str(), nullptr);
  if (ec != std::errc()) return std::nullopt;
  return value;
}

std::optional<std::int64_t> parse_int(std::string_view s) {
  s = without_plus(s);
  if (s.empty()) return std::nullopt;
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// The file in memory, read line by line (ASCII) or byte by byte (binary .msh data).
class Source {
 public:
  Source(fs::path path, std::string text) : path_(std::move(path)), text_(std::move(text)) {}

  [[noreturn]] void fail(int line, const std::string& message) const {
    throw MeshReadError(path_, line, message);
  }

  bool at_end() const { return pos_ >= text_.size(); }

  // The next line without its "\n" or "\r\n"; line() is then its 1-based number.
  std::string_view next_line() {
    line_ = next_line_number_;
    const auto newline = text_.find('\n', pos_);
    const auto end = newline == std::string::npos ? text_.size() : newline;
    std::string_view line(text_.data() + pos_, end - pos_);
    pos_ = newline == std::string::npos ? text_.size() : newline + 1;
    ++next_line_number_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  }

  int line() const { return line_; }
  int next_line_number() const { return next_line_number_; }
  std::size_t remaining() const { return text_.size() - pos_; }

  // Raw bytes of binary data. Newlines inside them still count, so the line numbers of later text
  // match what an editor shows.
  std::string_view take_bytes(std::size_t n, std::string_view what) {
    if (n > remaining())
      fail(next_line_number_, "binary " + std::string(what) + " is cut short (truncated file?)");
    const std::string_view bytes(text_.data() + pos_, n);
    pos_ += n;
    next_line_number_ += static_cast<int>(std::count(bytes.begin(), bytes.end(), '\n'));
    return bytes;
  }

 private:
  fs::path path_;
  std::string text_;
  std::size_t pos_ = 0;
  int line_ = 0;
  int next_line_number_ = 1;
};

Source load(const fs::path& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw MeshReadError(path, 0, "cannot access the file: " + ec.message());
  if (!fs::exists(status)) throw MeshReadError(path, 0, "file does not exist");
  if (fs::is_directory(status)) throw MeshReadError(path, 0, "is a directory, not a mesh file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshReadError(path, 0, "cannot open the file for reading");
  std::string text;
  std::array<char, 1 << 16> chunk;
  while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0)
    text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw MeshReadError(path, 0, "error while reading the file");
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw MeshReadError(path, 0, "file is empty");
  return Source(path, std::move(text));
}

// Names a field in an error message, such as "element 5: node id". Only spelled out on failure,
// so that reading stays cheap.
struct FieldName {
  std::string_view name;
  std::string_view owner_kind = {};  // "element", "node", "node set 'Disp'"
  std::int64_t owner = -1;

  std::string str() const {
    if (owner_kind.empty()) return std::string(name);
    return std::string(owner_kind) + (owner >= 0 ? " " + std::to_string(owner) : "") + ": " +
           std::string(name);
  }
};

std::int64_t parse_id(const Source& src, int line, std::string_view field, const FieldName& what,
                      std::int64_t min, std::int64_t max) {
  const auto value = parse_int(field);
  if (!value) src.fail(line, what.str() + " " + excerpt(field) + " is not an integer");
  if (*value < min || *value > max)
    src.fail(line, what.str() + " " + excerpt(field) + " is out of range (" + std::to_string(min) +
                       " to " + std::to_string(max) + ")");
  return *value;
}

double parse_coordinate(const Source& src, int line, std::int64_t node, std::string_view field) {
  const FieldName what{"coordinate", "node", node};
  if (field.empty()) src.fail(line, what.str() + " is empty");
  const auto value = parse_double(field);
  if (!value) src.fail(line, what.str() + " " + excerpt(field) + " is not a number");
  if (!std::isfinite(*value))
    src.fail(line, what.str() + " " + excerpt(field) + " is not a finite number");
  return *value;
}

// Nodes and tetrahedra under the file's own ids, before they are renumbered densely.
struct RawMesh {
  struct Tet {
    std::int64_t id;
    int line;
    std::array<std::int64_t, 4> node;
    std::int32_t region;
  };
  struct NodeEntry {
    NodeIndex index;
    int line;
  };

  NodeArray position;
  std::unordered_map<std::int64_t, NodeEntry> node_index;
  std::vector<Tet> tets;
  std::unordered_map<std::int64_t, int> element_line;  // every element id seen, tetrahedron or not

  void add_node(const Source& src, std::int64_t id, int line, const Eigen::Vector3d& p) {
    if (position.size() >= static_cast<std::size_t>(std::numeric_limits<NodeIndex>::max()))
      src.fail(line, "too many nodes");
    const auto [it, inserted] =
        node_index.try_emplace(id, NodeEntry{static_cast<NodeIndex>(position.size()), line});
    if (!inserted)
      src.fail(line, "node " + std::to_string(id) + " is defined twice (first on line " +
                         std::to_string(it->second.line) + ")");
    position.push_back(p);
  }

  void add_element_id(const Source& src, std::int64_t id, int line) {
    if (element_line.size() >= static_cast<std::size_t>(std::numeric_limits<TetIndex>::max()))
      src.fail(line, "too many elements");
    const auto [it, inserted] = element_line.try_emplace(id, line);
    if (!inserted)
      src.fail(line, "element " + std::to_string(id) + " is defined twice (first on line " +
                         std::to_string(it->second) + ")");
  }
};

// Renumbers the corners densely, turns inside-out elements right side out (a winding convention
// difference between tools, not an error) and rejects degenerate ones. Takes the positions out of
// raw; its id maps stay usable.
TetMesh build_tet_mesh(const Source& src, RawMesh& raw) {
  TetMesh mesh;
  mesh.rest_position_m = std::move(raw.position);
  for (auto& corner : mesh.corner) corner.reserve(raw.tets.size());
  mesh.region.reserve(raw.tets.size());
  for (const auto& t : raw.tets) {
    std::array<NodeIndex, 4> n{};
    std::array<Eigen::Vector3d, 4> p;
    for (int c = 0; c < 4; ++c) {
      const auto it = raw.node_index.find(t.node[c]);
      if (it == raw.node_index.end())
        src.fail(t.line, "element " + std::to_string(t.id) + " refers to node " +
                             std::to_string(t.node[c]) + ", which is not defined");
      n[c] = it->second.index;
      p[c] = mesh.rest_position_m.at(n[c]);
    }
    double longest_squared = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        longest_squared = std::max(longest_squared, (p[i] - p[j]).squaredNorm());
    const double longest = std::sqrt(longest_squared);
    const double volume = signed_tet_volume(p[0], p[1], p[2], p[3]);
    const auto where = [&] {
      return "element " + std::to_string(t.id) + " (line " + std::to_string(t.line) + ")";
    };
    if (!std::isfinite(volume))
      src.fail(t.line, where() + " has a volume too large to compute (coordinates out of range?)");
    if (std::abs(volume) <= 1e-12 * longest * longest * longest)
      src.fail(t.line, where() + " has zero volume (corner nodes " + std::to_string(t.node[0]) +
                           ", " + std::to_string(t.node[1]) + ", " + std::to_string(t.node[2]) +
                           ", " + std::to_string(t.node[3]) + ")");
    if (volume < 0.0) std::swap(n[2], n[3]);
    mesh.add_tet(n, t.region);
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Abaqus .inp

struct Keyword {
  std::string name;                                             // upper case, blanks removed
  std::vector<std::pair<std::string, std::string>> parameters;  // upper-case key, value as written

  const std::string* value(std::string_view key) const {
    for (const auto& [k, v] : parameters)
      if (k == key) return &v;
    return nullptr;
  }
  bool has(std::string_view key) const { return value(key) != nullptr; }
};

Keyword parse_keyword(std::string_view line) {
  Fields parts;
  append_comma_fields(line.substr(1), parts);
  Keyword keyword{keyword_name(parts[0]), {}};
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const auto eq = parts[i].find('=');
    std::string key = keyword_name(parts[i].substr(0, eq));
    if (key.empty()) continue;
    auto value = eq == std::string_view::npos ? std::string_view() : trim(parts[i].substr(eq + 1));
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"')
      value = value.substr(1, value.size() - 2);
    keyword.parameters.emplace_back(std::move(key), std::string(value));
  }
  return keyword;
}

// Element types that carry no tissue volume (surfaces, membranes, rigid facets, beams, trusses,
// connectors, springs, point masses): they are skipped, with their node counts so that their
// continuation lines can be told apart from new elements.
std::optional<std::size_t> skipped_element_nodes(const std::string& type) {
  static const std::map<std::string, std::size_t, std::less<>> kSkipped = {
      {"S3", 3},       {"S3R", 3},     {"STRI3", 3}, {"M3D3", 3},    {"SFM3D3", 3},  {"R3D3", 3},
      {"S4", 4},       {"S4R", 4},     {"M3D4", 4},  {"M3D4R", 4},   {"SFM3D4", 4},  {"SFM3D4R", 4},
      {"R3D4", 4},     {"T3D2", 2},    {"B31", 2},   {"CONN3D2", 2}, {"SPRINGA", 2}, {"SPRING2", 2},
      {"DASHPOTA", 2}, {"SPRING1", 1}, {"MASS", 1},  {"ROTARYI", 1}};
  const auto it = kSkipped.find(type);
  if (it == kSkipped.end()) return std::nullopt;
  return it->second;
}

class AbaqusReader {
 public:
  explicit AbaqusReader(Source& src) : src_(src) {}

  TetMesh read() {
    while (!src_.at_end()) {
      const auto line = trim(src_.next_line());
      if (line.empty() || line.starts_with("**")) continue;
      if (line[0] == '*') {
        finish_element();
        start_keyword(parse_keyword(line));
      } else {
        data_line(line);
      }
    }
    finish_element();
    if (raw_.position.size() == 0) src_.fail(0, "no nodes: the file has no *Node data");
    if (raw_.tets.empty())
      src_.fail(0, "no tetrahedra: the file has no *Element data of type C3D4, C3D4H or C3D4T");
    position_instance();
    TetMesh mesh = build_tet_mesh(src_, raw_);
    resolve_element_sets(mesh);
    resolve_node_sets(mesh);
    return mesh;
  }

 private:
  enum class Data { ignored, nodes, tets, skipped_elements, node_set, element_set, instance };

  struct SetEntry {
    std::int64_t first, last, step;
    int line;
  };
  struct SetDefinition {
    std::string name;  // as first written
    std::vector<SetEntry> entries;
    std::vector<std::pair<std::string, int>> element_sets;  // *Nset, elset=: nodes of these
  };
  struct Sets {
    std::vector<SetDefinition> definitions;
    std::map<std::string, std::size_t> index;  // by upper-case name: Abaqus names ignore case

    std::size_t find_or_add(const std::string& name) {
      const auto [it, inserted] = index.try_emplace(upper(name), definitions.size());
      if (inserted) definitions.push_back({name, {}, {}});
      return it->second;
    }
  };

  void start_keyword(const Keyword& k) {
    const int line = src_.line();
    data_ = Data::ignored;
    generate_ = false;
    element_set_.reset();
    node_set_.reset();
    if (k.name == "PART") {
      if (in_part_) src_.fail(line, "*Part inside another *Part (missing *End Part?)");
      seen_part_ = in_part_ = true;
      ++part_count_;
      const auto* name = k.value("NAME");
      part_name_ = name ? upper(*name) : std::string();
    } else if (k.name == "ENDPART") {
      in_part_ = false;
    } else if (k.name == "INSTANCE") {
      start_instance(k, line);
    } else if (k.name == "INCLUDE") {
      src_.fail(line, "*Include is not supported: paste the included file into this one");
    } else if (k.name == "NODE") {
      start_nodes(k, line);
    } else if (k.name == "ELEMENT") {
      start_elements(k, line);
    } else if (k.name == "NSET" || k.name == "ELSET") {
      start_set(k, line, k.name == "NSET");
    }
    // Every other keyword (*Heading, *Material, *Step, *Boundary, ...) and its data is ignored.
  }

  // Outside the part, *Node and *Element define assembly-level entities such as reference
  // points, which are not tissue.
  bool geometry_in_scope() const { return !seen_part_ || in_part_; }

  // Node and element ids restart in every part, so only one part may hold the mesh.
  void claim_mesh_part(int line) {
    if (!in_part_) return;
    if (mesh_part_ == 0) {
      mesh_part_ = part_count_;
      mesh_part_name_ = part_name_;
    } else if (mesh_part_ != part_count_) {
      src_.fail(line,
                "a second *Part with nodes or elements: only files with one meshed part are "
                "supported");
    }
  }

  void start_nodes(const Keyword& k, int line) {
    if (!geometry_in_scope()) return;
    if (k.has("INPUT")) src_.fail(line, "*Node, input= (nodes in another file) is not supported");
    if (const auto* system = k.value("SYSTEM"); system && upper(*system) != "R")
      src_.fail(line, "*Node, system=" + *system +
                          ": only Cartesian coordinates (system=R) are supported");
    claim_mesh_part(line);
    data_ = Data::nodes;
    if (const auto* nset = k.value("NSET")) node_set_ = node_sets_.find_or_add(*nset);
  }

  void start_elements(const Keyword& k, int line) {
    if (!geometry_in_scope()) return;
    const auto* type = k.value("TYPE");
    if (!type || type->empty()) src_.fail(line, "*Element has no type= parameter");
    if (k.has("INPUT"))
      src_.fail(line, "*Element, input= (elements in another file) is not supported");
    const std::string t = upper(*type);
    if (t == "C3D4" || t == "C3D4H" || t == "C3D4T") {
      claim_mesh_part(line);
      data_ = Data::tets;
      element_nodes_ = 4;
      if (const auto* elset = k.value("ELSET")) element_set_ = element_sets_.find_or_add(*elset);
    } else if (const auto nodes = skipped_element_nodes(t)) {
      data_ = Data::skipped_elements;
      element_nodes_ = *nodes;
    } else {
      src_.fail(line,
                "element type " + *type +
                    " is not supported; only 4-node tetrahedra (C3D4, C3D4H, C3D4T) are read");
    }
  }

  void start_set(const Keyword& k, int line, bool nodes) {
    const auto* name = k.value(nodes ? "NSET" : "ELSET");
    if (!name || name->empty())
      src_.fail(line, nodes ? "*Nset has no nset= parameter" : "*Elset has no elset= parameter");
    if (seen_part_ && !in_part_) {
      // An assembly-level set names assembly entities unless it points into the meshed instance.
      const auto* instance = k.value("INSTANCE");
      if (!instance || !mesh_instance_name_ || upper(*instance) != *mesh_instance_name_) return;
    }
    data_ = nodes ? Data::node_set : Data::element_set;
    generate_ = k.has("GENERATE");
    set_ = (nodes ? node_sets_ : element_sets_).find_or_add(*name);
    if (const auto* elset = nodes ? k.value("ELSET") : nullptr)
      node_sets_.definitions[set_].element_sets.emplace_back(*elset, line);
  }

  void start_instance(const Keyword& k, int line) {
    const auto* part = k.value("PART");
    if (!part || mesh_part_name_.empty() || upper(*part) != mesh_part_name_) return;
    if (mesh_instance_name_)
      src_.fail(line, "a second *Instance of part " + *part +
                          ": only files with one instance of the meshed part are supported");
    const auto* name = k.value("NAME");
    mesh_instance_name_ = name ? upper(*name) : std::string();
    data_ = Data::instance;
  }

  void data_line(std::string_view line) {
    switch (data_) {
      case Data::ignored:
        return;
      case Data::nodes:
        return node_line(line);
      case Data::tets:
      case Data::skipped_elements:
        return element_line(line);
      case Data::node_set:
      case Data::element_set:
        return set_line(line);
      case Data::instance:
        return instance_line(line);
    }
  }

  void node_line(std::string_view line) {
    const int n = src_.line();
    fields_.clear();
    append_comma_fields(line, fields_);
    const auto id = parse_id(src_, n, fields_[0], {"node id"}, 1, kMaxAbaqusId);
    // Up to three direction cosines of a normal may follow the coordinates; they are not used.
    if (fields_.size() < 4 || fields_.size() > 7)
      src_.fail(n, "node " + std::to_string(id) + ": expected a node id and 3 coordinates, found " +
                       std::to_string(fields_.size()) + " fields");
    const Eigen::Vector3d p(parse_coordinate(src_, n, id, fields_[1]),
                            parse_coordinate(src_, n, id, fields_[2]),
                            parse_coordinate(src_, n, id, fields_[3]));
    raw_.add_node(src_, id, n, p);
    if (node_set_) node_sets_.definitions[*node_set_].entries.push_back({id, id, 1, n});
  }

  // An element may continue on the next line when its line ends with a comma.
  void element_line(std::string_view line) {
    if (pending_.empty()) pending_line_ = src_.line();
    append_comma_fields(line, pending_);
    if (line.back() == ',' && pending_.size() < element_nodes_ + 1) return;
    finish_element();
  }

  void finish_element() {
    if (pending_.empty()) return;
    const int line = pending_line_;
    const auto id = parse_id(src_, line, pending_[0], {"element id"}, 1, kMaxAbaqusId);
    raw_.add_element_id(src_, id, line);
    if (data_ == Data::skipped_elements) {
      skipped_element_ids_.insert(id);
    } else {
      if (pending_.size() != 5)
        src_.fail(line, "element " + std::to_string(id) +
                            ": expected an element id and 4 node ids, found " +
                            std::to_string(pending_.size()) + " fields");
      RawMesh::Tet tet{id, line, {}, 0};
      for (int c = 0; c < 4; ++c)
        tet.node[c] =
            parse_id(src_, line, pending_[1 + c], {"node id", "element", id}, 1, kMaxAbaqusId);
      raw_.tets.push_back(tet);
      if (element_set_)
        element_sets_.definitions[*element_set_].entries.push_back({id, id, 1, line});
    }
    pending_.clear();
  }

  void set_line(std::string_view line) {
    const int n = src_.line();
    const bool nodes = data_ == Data::node_set;
    auto& set = (nodes ? node_sets_ : element_sets_).definitions[set_];
    const std::string what = (nodes ? "node set '" : "element set '") + set.name + "'";
    fields_.clear();
    append_comma_fields(line, fields_);
    if (generate_) {
      if (fields_.size() < 2 || fields_.size() > 3)
        src_.fail(n, what + ": generate expects 'first, last[, step]', found " +
                         std::to_string(fields_.size()) + " fields");
      const auto first = parse_id(src_, n, fields_[0], {"first id", what}, 1, kMaxAbaqusId);
      const auto last = parse_id(src_, n, fields_[1], {"last id", what}, 1, kMaxAbaqusId);
      const auto step =
          fields_.size() == 3 ? parse_id(src_, n, fields_[2], {"step", what}, 1, kMaxAbaqusId) : 1;
      if (last < first)
        src_.fail(n, what + ": generate runs backwards (" + std::to_string(first) + " to " +
                         std::to_string(last) + ")");
      set.entries.push_back({first, last, step, n});
      return;
    }
    for (const auto field : fields_) {
      if (!parse_int(field) && !field.empty() && std::isalpha(static_cast<unsigned char>(field[0])))
        src_.fail(n, what + ": member " + excerpt(field) +
                         " is a name; sets built from other sets are not supported");
      const auto id = parse_id(src_, n, field, {"member", what}, 1, kMaxAbaqusId);
      set.entries.push_back({id, id, 1, n});
    }
  }

  // First data line: translation; second: rotation about the axis through points a and b.
  void instance_line(std::string_view line) {
    const int n = src_.line();
    fields_.clear();
    append_comma_fields(line, fields_);
    const bool translation = !instance_translation_;
    if (!translation && instance_rotation_)
      src_.fail(n, "*Instance has more than two data lines (translation, rotation)");
    const std::size_t expected = translation ? 3 : 7;
    if (fields_.size() != expected)
      src_.fail(n, std::string("*Instance ") + (translation ? "translation" : "rotation") +
                       " needs " + std::to_string(expected) + " numbers, found " +
                       std::to_string(fields_.size()));
    std::array<double, 7> v{};
    for (std::size_t i = 0; i < expected; ++i) {
      const auto value = parse_double(fields_[i]);
      if (!value || !std::isfinite(*value))
        src_.fail(n, "*Instance positioning value " + excerpt(fields_[i]) + " is not a number");
      v[i] = *value;
    }
    if (translation) {
      instance_translation_ = Eigen::Vector3d(v[0], v[1], v[2]);
      return;
    }
    const Eigen::Vector3d a(v[0], v[1], v[2]), b(v[3], v[4], v[5]);
    if ((b - a).norm() == 0.0) src_.fail(n, "*Instance rotation axis has two equal points");
    instance_rotation_ = Eigen::Translation3d(a) *
                         Eigen::AngleAxisd(v[6] * std::numbers::pi / 180.0, (b - a).normalized()) *
                         Eigen::Translation3d(-a);
  }

  // Abaqus applies the instance translation first, then the rotation.
  void position_instance() {
    if (!instance_translation_) return;
    for (std::size_t i = 0; i < raw_.position.size(); ++i) {
      Eigen::Vector3d p = raw_.position.at(i) + *instance_translation_;
      if (instance_rotation_) p = *instance_rotation_ * p;
      raw_.position.set(i, p);
    }
  }

  // Generate ranges are walked id by id; every id must exist, so a range can never take more
  // steps than there are elements.
  void resolve_element_sets(TetMesh& mesh) {
    std::unordered_map<std::int64_t, TetIndex> tet_index;
    tet_index.reserve(raw_.tets.size());
    for (std::size_t i = 0; i < raw_.tets.size(); ++i)
      tet_index.emplace(raw_.tets[i].id, static_cast<TetIndex>(i));
    for (const auto& set : element_sets_.definitions) {
      std::vector<TetIndex> members;
      for (const auto& e : set.entries)
        for (auto id = e.first; id <= e.last; id += e.step) {
          if (const auto it = tet_index.find(id); it != tet_index.end())
            members.push_back(it->second);
          else if (!skipped_element_ids_.contains(id))
            src_.fail(e.line, "element set '" + set.name + "' refers to element " +
                                  std::to_string(id) + ", which is not defined");
        }
      std::sort(members.begin(), members.end());
      members.erase(std::unique(members.begin(), members.end()), members.end());
      mesh.element_sets[set.name] = std::move(members);
    }
  }

  void resolve_node_sets(TetMesh& mesh) {
    for (const auto& set : node_sets_.definitions) {
      std::vector<NodeIndex> members;
      for (const auto& e : set.entries)
        for (auto id = e.first; id <= e.last; id += e.step) {
          const auto it = raw_.node_index.find(id);
          if (it == raw_.node_index.end())
            src_.fail(e.line, "node set '" + set.name + "' refers to node " + std::to_string(id) +
                                  ", which is not defined");
          members.push_back(it->second.index);
        }
      for (const auto& [elset, line] : set.element_sets) {
        const auto it = element_sets_.index.find(upper(elset));
        if (it == element_sets_.index.end())
          src_.fail(line, "node set '" + set.name + "' is built from element set '" + elset +
                              "', which is not defined");
        for (const TetIndex e : mesh.element_sets[element_sets_.definitions[it->second].name])
          for (const NodeIndex n : mesh.tet(e)) members.push_back(n);
      }
      std::sort(members.begin(), members.end());
      members.erase(std::unique(members.begin(), members.end()), members.end());
      mesh.node_sets[set.name] = std::move(members);
    }
  }

  Source& src_;
  RawMesh raw_;
  Fields fields_;

  Data data_ = Data::ignored;
  std::size_t element_nodes_ = 0;
  Fields pending_;  // fields of an element that may continue on the next line
  int pending_line_ = 0;
  std::unordered_set<std::int64_t> skipped_element_ids_;

  Sets node_sets_, element_sets_;
  std::size_t set_ = 0;
  bool generate_ = false;
  std::optional<std::size_t> node_set_, element_set_;  // *Node, nset= and *Element, elset=

  bool seen_part_ = false, in_part_ = false;
  int part_count_ = 0, mesh_part_ = 0;
  std::string part_name_, mesh_part_name_;
  std::optional<std::string> mesh_instance_name_;
  std::optional<Eigen::Vector3d> instance_translation_;
  std::optional<Eigen::Affine3d> instance_rotation_;
};

// ---------------------------------------------------------------------------------------------
// Gmsh .msh

// Nodes per element of the Gmsh element types, needed to step over other types in binary files.
int gmsh_nodes_per_element(std::int64_t type) {
  static constexpr std::array<int, 32> kNodes = {0,  2,  3,  4,  4, 8, 6,  5,  3,  6, 9,
                                                 10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10,
                                                 12, 15, 15, 21, 4, 5, 6,  20, 35, 56};
  return type > 0 && type < static_cast<std::int64_t>(kNodes.size()) ? kNodes[type] : 0;
}

constexpr std::int64_t kGmshTet = 4;

class GmshReader {
 public:
  explicit GmshReader(Source& src) : src_(src) {}

  TetMesh read() {
    const auto first = next_nonblank();
    if (first == "$NOD" || first == "$NOE")
      src_.fail(src_.line(), "Gmsh format 1 ($NOD) is not supported; re-save as .msh 2.2 or 4.1");
    if (first != "$MeshFormat")
      src_.fail(src_.line(), "not a Gmsh mesh: expected $MeshFormat, found " + excerpt(first));
    read_format();
    while (true) {
      const auto header = next_nonblank();
      if (header.empty()) break;
      const int line = src_.line();
      if (header[0] != '$')
        src_.fail(line, "expected a section such as $Nodes or $Elements, found " + excerpt(header));
      const auto name = header.substr(1);
      if (name == "Nodes") {
        seen_nodes_ = true;
        version_ == Version::v2 ? read_nodes_v2() : read_nodes_v4();
      } else if (name == "Elements") {
        version_ == Version::v2 ? read_elements_v2() : read_elements_v4();
      } else if (name == "Entities" && version_ != Version::v2) {
        read_entities();
      } else if (name == "PartitionedEntities") {
        src_.fail(line, "partitioned meshes are not supported; save the mesh unpartitioned");
      } else if (name == "MeshFormat") {
        src_.fail(line, "a second $MeshFormat");
      } else if (name.starts_with("End")) {
        src_.fail(line, excerpt(header) + " without a matching $" + std::string(name.substr(3)));
      } else {
        skip_section(name);
      }
    }
    if (raw_.position.size() == 0)
      src_.fail(0, seen_nodes_ ? "no nodes: $Nodes is empty" : "no nodes: the file has no $Nodes");
    if (raw_.tets.empty())
      src_.fail(0, "no tetrahedra: the file has no elements of type 4 (4-node tetrahedron)");
    return build_tet_mesh(src_, raw_);
  }

 private:
  enum class Version { v2, v40, v41 };

  // The next line that is not blank, trimmed; empty at the end of the file.
  std::string_view next_nonblank() {
    while (!src_.at_end()) {
      const auto line = trim(src_.next_line());
      if (!line.empty()) return line;
    }
    return {};
  }

  // The next data line of a section. shortfall() says what is missing when the section or the
  // file ends first.
  template <class Shortfall>
  std::string_view data_line(std::string_view section, Shortfall&& shortfall) {
    const auto line = next_nonblank();
    if (line.empty())
      src_.fail(src_.line(), "the file ends inside $" + std::string(section) + ": " + shortfall());
    if (line[0] == '$')
      src_.fail(src_.line(),
                "$" + std::string(section) + " " + shortfall() + " before " + excerpt(line));
    return line;
  }

  const Fields& header(std::string_view section, std::size_t count, std::string_view layout) {
    const auto line = data_line(section, [] { return std::string("its header line is missing"); });
    split_whitespace(line, fields_);
    if (fields_.size() != count)
      src_.fail(src_.line(), "$" + std::string(section) + " header should be '" +
                                 std::string(layout) + "', found " + excerpt(line));
    return fields_;
  }

  void expect_end(std::string_view section) {
    const std::string end = "$End" + std::string(section);
    const auto line = next_nonblank();
    if (line.empty())
      src_.fail(src_.line(), "the file ends inside $" + std::string(section) + " (no " + end +
                                 "; truncated file?)");
    if (line != end)
      src_.fail(src_.line(), "expected " + end + " after the declared entries, found " +
                                 excerpt(line) + " (more entries than declared?)");
  }

  void skip_section(std::string_view name) {
    const std::string end = "$End" + std::string(name);
    while (!src_.at_end())
      if (trim(src_.next_line()) == end) return;
    src_.fail(src_.line(), "the file ends inside $" + std::string(name) + " (no " + end + ")");
  }

  std::int64_t count(std::string_view field, const FieldName& what) const {
    return parse_id(src_, src_.line(), field, what, 0, kMaxTag);
  }

  std::int64_t tag(std::string_view field, const FieldName& what) const {
    return parse_id(src_, src_.line(), field, what, 0, kMaxTag);
  }

  std::int32_t int32(std::string_view field, const FieldName& what) const {
    return static_cast<std::int32_t>(
        parse_id(src_, src_.line(), field, what, kMinInt32, kMaxInt32));
  }

  template <class T>
  T binary(std::string_view what) {
    const auto bytes = src_.take_bytes(sizeof(T), what);
    std::array<char, sizeof(T)> b{};
    std::memcpy(b.data(), bytes.data(), sizeof(T));
    if (swap_) std::reverse(b.begin(), b.end());
    T value;
    std::memcpy(&value, b.data(), sizeof(T));
    return value;
  }

  // A size_t count or tag of a binary .msh 4 file.
  std::int64_t binary_size(std::string_view what) {
    const int line = src_.next_line_number();
    const auto value = binary<std::uint64_t>(what);
    if (value > static_cast<std::uint64_t>(kMaxTag))
      src_.fail(line, "binary " + std::string(what) + ": value " + std::to_string(value) +
                          " is out of range");
    return static_cast<std::int64_t>(value);
  }

  double binary_coordinate(std::int64_t node, int axis) {
    const int line = src_.next_line_number();
    const double value = binary<double>("$Nodes");
    if (!std::isfinite(value))
      src_.fail(line, "node " + std::to_string(node) + ": coordinate " + std::to_string(axis + 1) +
                          " is not a finite number");
    return value;
  }

  // Checked before reading or reserving anything for a declared count, so that a corrupt count
  // ends in an error rather than a huge allocation.
  void require_bytes(std::int64_t count, std::size_t item_bytes, std::string_view what) const {
    if (item_bytes > 0 && static_cast<std::uint64_t>(count) > src_.remaining() / item_bytes)
      src_.fail(src_.next_line_number(), "binary " + std::string(what) + " declares " +
                                             std::to_string(count) +
                                             " entries, more than the rest of the file holds "
                                             "(truncated file?)");
  }

  void read_format() {
    const auto line =
        data_line("MeshFormat", [] { return std::string("its version line is missing"); });
    const int n = src_.line();
    split_whitespace(line, fields_);
    if (fields_.size() != 3)
      src_.fail(n, "$MeshFormat should be 'version file-type data-size', found " + excerpt(line));
    const auto version = parse_double(fields_[0]);
    if (version && *version >= 2.0 && *version < 3.0)
      version_ = Version::v2;
    else if (version && *version == 4.0)
      version_ = Version::v40;
    else if (version && *version == 4.1)
      version_ = Version::v41;
    else
      src_.fail(n, "unsupported .msh version " + excerpt(fields_[0]) +
                       "; this reader handles 2.2, 4.0 and 4.1");
    if (fields_[1] != "0" && fields_[1] != "1")
      src_.fail(
          n, "$MeshFormat file-type must be 0 (ASCII) or 1 (binary), found " + excerpt(fields_[1]));
    binary_ = fields_[1] == "1";
    if (binary_) {
      if (version_ == Version::v40)
        src_.fail(n,
                  "binary .msh 4.0 is not supported (Gmsh itself reads 4.0 only as ASCII); "
                  "re-save as 4.1 or ASCII");
      if (fields_[2] != "8")
        src_.fail(n, "binary .msh with data-size " + excerpt(fields_[2]) +
                         " is not supported (expected 8)");
      // The integer 1, written in the byte order of the machine that wrote the file.
      const int marker_line = src_.next_line_number();
      const auto marker = binary<std::uint32_t>("$MeshFormat");
      if (marker == 0x01000000u)
        swap_ = true;
      else if (marker != 1u)
        src_.fail(marker_line,
                  "binary .msh: the byte-order marker after the version line is not 1");
    }
    expect_end("MeshFormat");
  }

  void read_nodes_v2() {
    const auto total = count(header("Nodes", 1, "number-of-nodes")[0], {"number of nodes"});
    if (binary_) {
      require_bytes(total, 4 + 3 * 8, "$Nodes");
      for (std::int64_t i = 0; i < total; ++i) {
        const int line = src_.next_line_number();
        const auto id = binary<std::int32_t>("$Nodes");
        if (id < 0) src_.fail(line, "node tag " + std::to_string(id) + " is negative");
        Eigen::Vector3d p;
        for (int axis = 0; axis < 3; ++axis) p[axis] = binary_coordinate(id, axis);
        raw_.add_node(src_, id, line, p);
      }
    } else {
      for (std::int64_t i = 0; i < total; ++i) {
        split_whitespace(data_line("Nodes", [&] { return declared(total, "nodes", i); }), fields_);
        const auto id = tag(fields_[0], {"node tag"});
        read_ascii_node(id, 1);
      }
    }
    expect_end("Nodes");
  }

  // Coordinates x y z start at fields_[first]; parametric coordinates after them are not used.
  void read_ascii_node(std::int64_t id, std::size_t first, std::size_t parametric = 0) {
    const int line = src_.line();
    if (fields_.size() != first + 3 + parametric)
      src_.fail(line, "node " + std::to_string(id) + ": expected " +
                          (first ? "a node tag and " : "") + std::to_string(3 + parametric) +
                          " coordinates, found " + std::to_string(fields_.size()) + " fields");
    const Eigen::Vector3d p(parse_coordinate(src_, line, id, fields_[first]),
                            parse_coordinate(src_, line, id, fields_[first + 1]),
                            parse_coordinate(src_, line, id, fields_[first + 2]));
    raw_.add_node(src_, id, line, p);
  }

  static std::string declared(std::int64_t total, std::string_view what, std::int64_t listed) {
    return "declares " + std::to_string(total) + " " + std::string(what) + " but lists " +
           std::to_string(listed);
  }

  void read_elements_v2() {
    const auto total =
        count(header("Elements", 1, "number-of-elements")[0], {"number of elements"});
    if (binary_) return read_binary_elements_v2(total);
    for (std::int64_t i = 0; i < total; ++i) {
      split_whitespace(data_line("Elements", [&] { return declared(total, "elements", i); }),
                       fields_);
      const int line = src_.line();
      if (fields_.size() < 3)
        src_.fail(line, "an element line needs at least 'tag type number-of-tags', found " +
                            std::to_string(fields_.size()) + " fields");
      const auto id = tag(fields_[0], {"element tag"});
      const auto type = int32(fields_[1], {"type", "element", id});
      const auto tags = count(fields_[2], {"number of tags", "element", id});
      if (tags > static_cast<std::int64_t>(fields_.size()) - 3)
        src_.fail(line, "element " + std::to_string(id) + " declares " + std::to_string(tags) +
                            " tags but has only " + std::to_string(fields_.size() - 3) +
                            " more fields");
      raw_.add_element_id(src_, id, line);
      if (type != kGmshTet) continue;
      const auto first_node = static_cast<std::size_t>(3 + tags);
      if (fields_.size() != first_node + 4)
        src_.fail(line, "element " + std::to_string(id) + ": a 4-node tetrahedron with " +
                            std::to_string(tags) + " tags needs " + std::to_string(first_node + 4) +
                            " fields, found " + std::to_string(fields_.size()));
      RawMesh::Tet tet{
          id, line, {}, tags > 0 ? int32(fields_[3], {"physical tag", "element", id}) : 0};
      for (int c = 0; c < 4; ++c)
        tet.node[c] = tag(fields_[first_node + c], {"node tag", "element", id});
      raw_.tets.push_back(tet);
    }
    expect_end("Elements");
  }

  // Blocks of elements of one type: header (type, count, number of tags), then per element its
  // tag, tags and nodes, all 4-byte ints.
  void read_binary_elements_v2(std::int64_t total) {
    std::int64_t listed = 0;
    while (listed < total) {
      const int line = src_.next_line_number();
      const auto type = binary<std::int32_t>("$Elements");
      const auto count = binary<std::int32_t>("$Elements");
      const auto tags = binary<std::int32_t>("$Elements");
      if (count < 0 || tags < 0 || count > total - listed)
        src_.fail(line, "binary $Elements: a block of " + std::to_string(count) +
                            " elements with " + std::to_string(tags) + " tags does not fit the " +
                            std::to_string(total) + " elements declared");
      const int nodes = gmsh_nodes_per_element(type);
      if (nodes == 0)
        src_.fail(line, "binary $Elements: element type " + std::to_string(type) +
                            " is unknown, so its size is unknown");
      const std::size_t ints = 1 + static_cast<std::size_t>(tags) + static_cast<std::size_t>(nodes);
      require_bytes(count, 4 * ints, "$Elements");
      for (std::int32_t j = 0; j < count; ++j) {
        const int element_line = src_.next_line_number();
        const auto id = binary<std::int32_t>("$Elements");
        std::int32_t region = 0;
        for (std::int32_t t = 0; t < tags; ++t) {
          const auto value = binary<std::int32_t>("$Elements");
          if (t == 0) region = value;
        }
        RawMesh::Tet tet{id, element_line, {}, region};
        for (int c = 0; c < nodes; ++c) {
          const auto node = binary<std::int32_t>("$Elements");
          if (c < 4) tet.node[c] = node;
        }
        if (id < 0) src_.fail(element_line, "element tag " + std::to_string(id) + " is negative");
        raw_.add_element_id(src_, id, element_line);
        if (type == kGmshTet) raw_.tets.push_back(tet);
      }
      listed += count;
    }
    expect_end("Elements");
  }

  void read_entities() {
    std::array<std::int64_t, 4> counts{};
    if (binary_) {
      for (auto& c : counts) c = binary_size("$Entities");
    } else {
      const auto& h = header("Entities", 4, "numPoints numCurves numSurfaces numVolumes");
      for (int d = 0; d < 4; ++d) counts[d] = count(h[d], {"number of entities"});
    }
    for (int dim = 0; dim < 4; ++dim)
      for (std::int64_t i = 0; i < counts[dim]; ++i)
        binary_ ? read_binary_entity(dim) : read_ascii_entity(dim, counts[dim], i);
    expect_end("Entities");
  }

  // "tag bounding-box numPhysicalTags physicalTag... [numBounding bounding...]"; a point has a
  // 3-number box in 4.1 and a 6-number one in 4.0.
  void read_ascii_entity(int dim, std::int64_t total, std::int64_t listed) {
    split_whitespace(data_line("Entities",
                               [&] {
                                 return declared(
                                     total, "entities of dimension " + std::to_string(dim), listed);
                               }),
                     fields_);
    const int line = src_.line();
    const std::size_t box = (dim == 0 && version_ == Version::v41) ? 3 : 6;
    if (fields_.size() < box + 2)
      src_.fail(line, "an entity line of dimension " + std::to_string(dim) + " needs at least " +
                          std::to_string(box + 2) + " fields, found " +
                          std::to_string(fields_.size()));
    const auto entity = int32(fields_[0], {"entity tag"});
    const auto physicals = count(fields_[1 + box], {"number of physical tags"});
    if (physicals > static_cast<std::int64_t>(fields_.size() - box - 2))
      src_.fail(line, "entity " + std::to_string(entity) + " declares " +
                          std::to_string(physicals) + " physical tags but the line is shorter");
    if (dim == 3 && physicals > 0)
      volume_physical_[entity] = int32(fields_[2 + box], {"physical tag"});
  }

  void read_binary_entity(int dim) {
    const auto entity = binary<std::int32_t>("$Entities");
    src_.take_bytes((dim == 0 ? 3 : 6) * sizeof(double), "$Entities");
    const auto physicals = binary_size("$Entities");
    require_bytes(physicals, sizeof(std::int32_t), "$Entities");
    for (std::int64_t p = 0; p < physicals; ++p) {
      const auto physical = binary<std::int32_t>("$Entities");
      if (dim == 3 && p == 0) volume_physical_[entity] = physical;
    }
    if (dim > 0) {
      const auto bounding = binary_size("$Entities");
      require_bytes(bounding, sizeof(std::int32_t), "$Entities");
      src_.take_bytes(static_cast<std::size_t>(bounding) * sizeof(std::int32_t), "$Entities");
    }
  }

  struct Block {
    int line;
    int dim;
    std::int32_t entity;
    std::int64_t third;  // parametric flag (nodes) or element type (elements)
    std::int64_t count;
  };

  // 4.1 writes "dim entity ..." and 4.0 "entity dim ..."; binary is 4.1 only.
  Block block_header(std::string_view section, std::int64_t blocks, std::int64_t b) {
    Block block{};
    if (binary_) {
      const int line = block.line = src_.next_line_number();
      block.dim = binary<std::int32_t>(section);
      block.entity = binary<std::int32_t>(section);
      block.third = binary<std::int32_t>(section);
      block.count = binary_size(section);
      if (block.dim < 0 || block.dim > 3)
        src_.fail(line, "binary " + std::string(section) + ": entity dimension " +
                            std::to_string(block.dim) + " is not 0 to 3");
      return block;
    }
    const auto line = data_line(section, [&] { return declared(blocks, "entity blocks", b); });
    block.line = src_.line();
    split_whitespace(line, fields_);
    if (fields_.size() != 4)
      src_.fail(src_.line(), "a $" + std::string(section) +
                                 " block header needs 4 numbers, found " + excerpt(line));
    const bool v41 = version_ == Version::v41;
    block.dim = int32(fields_[v41 ? 0 : 1], {"entity dimension"});
    block.entity = int32(fields_[v41 ? 1 : 0], {"entity tag"});
    block.third = int32(fields_[2], {section == "Nodes" ? "parametric flag" : "element type"});
    block.count = count(fields_[3], {"number of entries in the block"});
    if (block.dim < 0 || block.dim > 3)
      src_.fail(src_.line(), "entity dimension " + std::to_string(block.dim) + " is not 0 to 3");
    return block;
  }

  struct SectionCounts {
    int line;
    std::int64_t blocks, total;
  };

  SectionCounts section_counts(std::string_view section) {
    if (binary_) {
      const int line = src_.next_line_number();
      const auto blocks = binary_size(section);
      const auto total = binary_size(section);
      binary_size(section);  // min and max tag: not needed
      binary_size(section);
      return {line, blocks, total};
    }
    const auto& h = version_ == Version::v41
                        ? header(section, 4, "numEntityBlocks total minTag maxTag")
                        : header(section, 2, "numEntityBlocks total");
    return {src_.line(), count(h[0], {"number of entity blocks"}),
            count(h[1], {"number of entries"})};
  }

  void read_nodes_v4() {
    const auto [header_line, blocks, total] = section_counts("Nodes");
    std::int64_t listed = 0;
    std::vector<std::int64_t> tags;
    for (std::int64_t b = 0; b < blocks; ++b) {
      const auto block = block_header("Nodes", blocks, b);
      if (block.third != 0 && block.third != 1)
        src_.fail(src_.line(), "the parametric flag of a $Nodes block must be 0 or 1");
      const std::size_t parametric = block.third ? static_cast<std::size_t>(block.dim) : 0;
      const auto shortfall = [&, n = block.count](std::int64_t i) {
        return "has a block that " + declared(n, "nodes", i);
      };
      if (binary_) {
        require_bytes(block.count, 8, "$Nodes");
        tags.resize(static_cast<std::size_t>(block.count));
        for (auto& t : tags) t = binary_size("$Nodes");
        require_bytes(block.count, 8 * (3 + parametric), "$Nodes");
        for (const auto id : tags) {
          const int line = src_.next_line_number();
          Eigen::Vector3d p;
          for (int axis = 0; axis < 3; ++axis) p[axis] = binary_coordinate(id, axis);
          src_.take_bytes(8 * parametric, "$Nodes");
          raw_.add_node(src_, id, line, p);
        }
      } else if (version_ == Version::v41) {
        // All tags of the block first, then all coordinates.
        tags.clear();
        for (std::int64_t i = 0; i < block.count; ++i) {
          const auto line = data_line("Nodes", [&] { return shortfall(i); });
          split_whitespace(line, fields_);
          if (fields_.size() != 1)
            src_.fail(src_.line(), "$Nodes block on line " + std::to_string(block.line) +
                                       ": expected one node tag per line, found " + excerpt(line));
          tags.push_back(tag(fields_[0], {"node tag"}));
        }
        for (std::int64_t i = 0; i < block.count; ++i) {
          split_whitespace(data_line("Nodes", [&] { return shortfall(i); }), fields_);
          read_ascii_node(tags[static_cast<std::size_t>(i)], 0, parametric);
        }
      } else {
        for (std::int64_t i = 0; i < block.count; ++i) {
          split_whitespace(data_line("Nodes", [&] { return shortfall(i); }), fields_);
          read_ascii_node(tag(fields_[0], {"node tag"}), 1, parametric);
        }
      }
      listed += block.count;
    }
    if (listed != total)
      src_.fail(header_line, "$Nodes " + declared(total, "nodes", listed) + " in its blocks");
    expect_end("Nodes");
  }

  void read_elements_v4() {
    const auto [header_line, blocks, total] = section_counts("Elements");
    std::int64_t listed = 0;
    for (std::int64_t b = 0; b < blocks; ++b) {
      const auto block = block_header("Elements", blocks, b);
      const std::int64_t type = block.third;
      std::int32_t region = 0;
      if (const auto it = volume_physical_.find(block.entity);
          block.dim == 3 && it != volume_physical_.end())
        region = it->second;
      if (binary_) {
        const int nodes = gmsh_nodes_per_element(type);
        if (nodes == 0)
          src_.fail(src_.line(), "binary $Elements: element type " + std::to_string(type) +
                                     " is unknown, so its size is unknown");
        require_bytes(block.count, 8 * (1 + static_cast<std::size_t>(nodes)), "$Elements");
        for (std::int64_t i = 0; i < block.count; ++i) {
          const int line = src_.next_line_number();
          RawMesh::Tet tet{binary_size("$Elements"), line, {}, region};
          for (int c = 0; c < nodes; ++c) {
            const auto node = binary_size("$Elements");
            if (c < 4) tet.node[c] = node;
          }
          raw_.add_element_id(src_, tet.id, line);
          if (type == kGmshTet) raw_.tets.push_back(tet);
        }
      } else {
        for (std::int64_t i = 0; i < block.count; ++i) {
          split_whitespace(
              data_line("Elements",
                        [&] { return "has a block that " + declared(block.count, "elements", i); }),
              fields_);
          const int line = src_.line();
          const auto id = tag(fields_[0], {"element tag"});
          raw_.add_element_id(src_, id, line);
          if (type != kGmshTet) continue;
          if (fields_.size() != 5)
            src_.fail(line, "element " + std::to_string(id) +
                                ": expected an element tag and 4 node tags, found " +
                                std::to_string(fields_.size()) + " fields");
          RawMesh::Tet tet{id, line, {}, region};
          for (int c = 0; c < 4; ++c)
            tet.node[c] = tag(fields_[1 + c], {"node tag", "element", id});
          raw_.tets.push_back(tet);
        }
      }
      listed += block.count;
    }
    if (listed != total)
      src_.fail(header_line, "$Elements " + declared(total, "elements", listed) + " in its blocks");
    expect_end("Elements");
  }

  Source& src_;
  RawMesh raw_;
  Fields fields_;
  Version version_ = Version::v2;
  bool binary_ = false;
  bool swap_ = false;  // binary file written with the other byte order
  bool seen_nodes_ = false;
  std::unordered_map<std::int32_t, std::int32_t> volume_physical_;  // volume entity -> physical
};

}  // namespace

TetMesh read_abaqus_inp(const std::filesystem::path& file) {
  Source src = load(file);
  return AbaqusReader(src).read();
}

TetMesh read_gmsh_msh(const std::filesystem::path& file) {
  Source src = load(file);
  return GmshReader(src).read();
}

TetMesh read_tet_mesh(const std::filesystem::path& file) {
  const std::string extension = upper(file.extension().string());
  if (extension == ".INP") return read_abaqus_inp(file);
  if (extension == ".MSH") return read_gmsh_msh(file);
  throw MeshReadError(
      file, 0,
      (extension.empty() ? std::string("the file name has no extension")
                         : "unknown mesh file extension " + excerpt(file.extension().string())) +
          "; expected .inp (Abaqus) or .msh (Gmsh)");
}

}  // namespace liversim

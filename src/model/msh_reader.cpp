#include "model/msh_reader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/config_error.h"

namespace sedbridge::model {
namespace {

using config::ConfigError;

// Walks the file line by line, remembering the line number for messages.
class LineCursor {
 public:
  LineCursor(const std::string& text, std::string file) : in_(text), file_(std::move(file)) {}

  // Next line with its trailing '\r' removed; false at end of file.
  bool Next(std::string* line) {
    if (!std::getline(in_, *line)) return false;
    ++line_number_;
    if (!line->empty() && line->back() == '\r') line->pop_back();
    return true;
  }
  // Next line, which must exist; `what` says what was expected.
  std::string Require(const std::string& what) {
    std::string line;
    if (!Next(&line)) Fail("unexpected end of file, expected " + what);
    return line;
  }
  // Next line split into whitespace-separated tokens.
  std::vector<std::string> Tokens(const std::string& what) {
    std::istringstream ss(Require(what));
    std::vector<std::string> tokens;
    std::string t;
    while (ss >> t) tokens.push_back(t);
    return tokens;
  }
  [[noreturn]] void Fail(const std::string& message) const {
    throw ConfigError({file_, line_number_, 0}, message);
  }
  int line() const { return line_number_; }
  const std::string& file() const { return file_; }

 private:
  std::istringstream in_;
  std::string file_;
  int line_number_ = 0;
};

long long ToInt(const LineCursor& c, const std::string& token, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(token.c_str(), &end, 10);
  if (token.empty() || *end != '\0' || errno != 0) {
    c.Fail("malformed " + what + ": expected an integer, got '" + token + "'");
  }
  return v;
}

double ToDouble(const LineCursor& c, const std::string& token, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (token.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
    c.Fail("malformed " + what + ": expected a finite number, got '" + token + "'");
  }
  return v;
}

std::size_t ToTag(const LineCursor& c, const std::string& token, const std::string& what) {
  const long long v = ToInt(c, token, what);
  if (v <= 0) c.Fail("malformed " + what + ": tags must be positive, got '" + token + "'");
  return static_cast<std::size_t>(v);
}

void ExpectCount(const LineCursor& c, const std::vector<std::string>& tokens, std::size_t n,
                 const std::string& what) {
  if (tokens.size() != n) {
    c.Fail("malformed " + what + ": expected " + std::to_string(n) + " values, got " +
           std::to_string(tokens.size()));
  }
}

void ExpectEnd(LineCursor& c, const std::string& section) {
  const std::string end = "$End" + section;
  const std::string line = c.Require(end);
  if (line != end) c.Fail("expected '" + end + "', got '" + line + "'");
}

void ReadMeshFormat(LineCursor& c) {
  const auto t = c.Tokens("the mesh format line");
  ExpectCount(c, t, 3, "$MeshFormat line");
  if (t[0] != "4.1") {
    c.Fail("unsupported MSH version " + t[0] + " (only 4.1 is read; re-export from Gmsh with "
           "Mesh.MshFileVersion = 4.1)");
  }
  if (t[1] != "0") c.Fail("binary MSH files are not supported (export as ASCII, Mesh.Binary = 0)");
  ExpectEnd(c, "MeshFormat");
}

void ReadPhysicalNames(LineCursor& c, MshFile* m) {
  const auto head = c.Tokens("the number of physical names");
  ExpectCount(c, head, 1, "$PhysicalNames count");
  const long long n = ToInt(c, head[0], "$PhysicalNames count");
  for (long long i = 0; i < n; ++i) {
    const std::string line = c.Require("a physical name");
    std::istringstream ss(line);
    std::string dim, tag;
    ss >> dim >> tag;
    const auto open = line.find('"');
    const auto close = line.rfind('"');
    if (open == std::string::npos || close == open) {
      c.Fail("malformed physical name: expected 'dim tag \"name\"', got '" + line + "'");
    }
    MshPhysicalName p;
    p.dim = static_cast<int>(ToInt(c, dim, "physical name dimension"));
    p.tag = static_cast<int>(ToInt(c, tag, "physical name tag"));
    p.name = line.substr(open + 1, close - open - 1);
    p.line = c.line();
    m->physical_names.push_back(p);
  }
  ExpectEnd(c, "PhysicalNames");
}

void ReadEntities(LineCursor& c, MshFile* m) {
  const auto head = c.Tokens("entity counts");
  ExpectCount(c, head, 4, "$Entities counts");
  for (int dim = 0; dim < 4; ++dim) {
    const long long n = ToInt(c, head[dim], "$Entities count");
    for (long long i = 0; i < n; ++i) {
      const auto t = c.Tokens("an entity");
      // point: tag x y z nphys ...; others: tag 6 bbox values nphys ... nbound ...
      const std::size_t phys_at = dim == 0 ? 4 : 7;
      if (t.size() < phys_at + 1) c.Fail("malformed entity line (too few values)");
      const int tag = static_cast<int>(ToInt(c, t[0], "entity tag"));
      const long long nphys = ToInt(c, t[phys_at], "entity physical tag count");
      if (nphys < 0 || t.size() < phys_at + 1 + static_cast<std::size_t>(nphys)) {
        c.Fail("malformed entity line (physical tag count " + t[phys_at] + ")");
      }
      std::vector<int> phys;
      for (long long k = 0; k < nphys; ++k) {
        phys.push_back(std::abs(static_cast<int>(ToInt(c, t[phys_at + 1 + k], "physical tag"))));
      }
      if (dim > 0) {  // bounding entities follow; check the count matches
        const std::size_t nb_at = phys_at + 1 + nphys;
        if (t.size() < nb_at + 1) c.Fail("malformed entity line (missing bounding entity count)");
        const long long nb = ToInt(c, t[nb_at], "bounding entity count");
        if (nb < 0 || t.size() != nb_at + 1 + static_cast<std::size_t>(nb)) {
          c.Fail("malformed entity line (bounding entity count " + t[nb_at] + ")");
        }
      }
      m->entity_physical_tags[{dim, tag}] = std::move(phys);
    }
  }
  ExpectEnd(c, "Entities");
}

void ReadNodes(LineCursor& c, MshFile* m) {
  const auto head = c.Tokens("node counts");
  ExpectCount(c, head, 4, "$Nodes header");
  const int header_line = c.line();
  const long long blocks = ToInt(c, head[0], "$Nodes block count");
  const long long total = ToInt(c, head[1], "$Nodes node count");
  if (blocks < 0 || total < 0) c.Fail("malformed $Nodes header (negative count)");
  const std::size_t first = m->node_tags.size();
  // The header is user input: do not trust it with a huge allocation.
  const std::size_t expected = static_cast<std::size_t>(std::min<long long>(total, 1 << 20));
  m->node_tags.reserve(first + expected);
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(expected);
  for (long long b = 0; b < blocks; ++b) {
    const auto bh = c.Tokens("a node block header");
    ExpectCount(c, bh, 4, "node block header");
    const long long dim = ToInt(c, bh[0], "node block entity dimension");
    const long long parametric = ToInt(c, bh[2], "node block parametric flag");
    const long long n = ToInt(c, bh[3], "node block size");
    if (n < 0) c.Fail("malformed node block header (negative size)");
    const std::size_t block_first = m->node_tags.size();
    for (long long i = 0; i < n; ++i) {
      const auto t = c.Tokens("a node tag");
      ExpectCount(c, t, 1, "node tag line");
      const std::size_t tag = ToTag(c, t[0], "node tag");
      if (!m->node_index.emplace(tag, static_cast<int>(m->node_tags.size())).second) {
        c.Fail("node " + std::to_string(tag) + " is defined twice");
      }
      m->node_tags.push_back(tag);
    }
    const std::size_t ncoord = 3 + (parametric ? static_cast<std::size_t>(dim) : 0);
    for (long long i = 0; i < n; ++i) {
      const auto t = c.Tokens("node coordinates");
      if (t.size() != ncoord) {
        c.Fail("malformed coordinates of node " + std::to_string(m->node_tags[block_first + i]) +
               ": expected " + std::to_string(ncoord) + " values, got " + std::to_string(t.size()));
      }
      positions.emplace_back(ToDouble(c, t[0], "node x"), ToDouble(c, t[1], "node y"),
                             ToDouble(c, t[2], "node z"));
    }
  }
  if (static_cast<long long>(m->node_tags.size() - first) != total) {
    throw config::ConfigError({c.file(), header_line, 0},
                              "$Nodes header announces " + std::to_string(total) +
                                  " nodes, blocks hold " + std::to_string(m->node_tags.size() - first));
  }
  Eigen::Matrix3Xd all(3, m->node_tags.size());
  if (first > 0) all.leftCols(first) = m->node_positions;
  for (std::size_t i = 0; i < positions.size(); ++i) all.col(first + i) = positions[i];
  m->node_positions = std::move(all);
  ExpectEnd(c, "Nodes");
}

void ReadElements(LineCursor& c, MshFile* m) {
  const auto head = c.Tokens("element counts");
  ExpectCount(c, head, 4, "$Elements header");
  const int header_line = c.line();
  const long long blocks = ToInt(c, head[0], "$Elements block count");
  const long long total = ToInt(c, head[1], "$Elements element count");
  if (blocks < 0 || total < 0) c.Fail("malformed $Elements header (negative count)");
  long long seen = 0;
  for (long long b = 0; b < blocks; ++b) {
    const auto bh = c.Tokens("an element block header");
    ExpectCount(c, bh, 4, "element block header");
    const int dim = static_cast<int>(ToInt(c, bh[0], "element block entity dimension"));
    const int entity = static_cast<int>(ToInt(c, bh[1], "element block entity tag"));
    const int type = static_cast<int>(ToInt(c, bh[2], "element type"));
    const long long n = ToInt(c, bh[3], "element block size");
    const int nodes = MshNodesPerElement(type);
    if (nodes < 0) c.Fail("unknown Gmsh element type " + std::to_string(type));
    if (n < 0) c.Fail("malformed element block header (negative size)");
    for (long long i = 0; i < n; ++i) {
      const auto t = c.Tokens("an element");
      const std::size_t tag = ToTag(c, t.empty() ? "" : t[0], "element tag");
      if (t.size() != static_cast<std::size_t>(nodes) + 1) {
        c.Fail("malformed element " + std::to_string(tag) + ": type " + std::to_string(type) +
               " needs " + std::to_string(nodes) + " nodes, got " + std::to_string(t.size() - 1));
      }
      ++seen;
      if (dim < 2) continue;  // points and lines carry nothing the model needs
      MshElement e;
      e.tag = tag;
      e.type = type;
      e.entity_dim = dim;
      e.entity_tag = entity;
      e.line = c.line();
      e.node_tags.reserve(nodes);
      for (int k = 0; k < nodes; ++k) e.node_tags.push_back(ToTag(c, t[1 + k], "element node tag"));
      m->elements.push_back(std::move(e));
    }
  }
  if (seen != total) {
    throw config::ConfigError({c.file(), header_line, 0},
                              "$Elements header announces " + std::to_string(total) +
                                  " elements, blocks hold " + std::to_string(seen));
  }
  ExpectEnd(c, "Elements");
}

void SkipSection(LineCursor& c, const std::string& section) {
  const std::string end = "$End" + section;
  std::string line;
  while (c.Next(&line)) {
    if (line == end) return;
  }
  c.Fail("section $" + section + " has no " + end);
}

// Checks what needs the whole file: element nodes defined, element tags unique.
void Validate(const MshFile& m) {
  std::unordered_map<std::size_t, int> element_lines;
  for (const MshElement& e : m.elements) {
    if (!element_lines.emplace(e.tag, e.line).second) {
      throw ConfigError({m.file, e.line, 0}, "element " + std::to_string(e.tag) +
                                                 " is defined twice (first on line " +
                                                 std::to_string(element_lines[e.tag]) + ")");
    }
    for (std::size_t n : e.node_tags) {
      if (!m.node_index.count(n)) {
        throw ConfigError({m.file, e.line, 0}, "element " + std::to_string(e.tag) +
                                                   " references node " + std::to_string(n) +
                                                   ", which is not defined in $Nodes");
      }
    }
  }
}

}  // namespace

int MshNodesPerElement(int type) {
  switch (type) {
    case 1: return 2;    // line
    case 2: return 3;    // triangle
    case 3: return 4;    // quadrangle
    case 4: return 4;    // tetrahedron
    case 5: return 8;    // hexahedron
    case 6: return 6;    // prism
    case 7: return 5;    // pyramid
    case 8: return 3;    // 3-node line
    case 9: return 6;    // 6-node triangle
    case 10: return 9;   // 9-node quadrangle
    case 11: return 10;  // 10-node tetrahedron
    case 12: return 27;  // 27-node hexahedron
    case 13: return 18;  // 18-node prism
    case 14: return 14;  // 14-node pyramid
    case 15: return 1;   // point
    case 16: return 8;   // 8-node quadrangle
    case 17: return 20;  // 20-node hexahedron
    case 18: return 15;  // 15-node prism
    case 19: return 13;  // 13-node pyramid
    default: return -1;
  }
}

const std::vector<int>& MshFile::PhysicalTagsOf(const MshElement& e) const {
  static const std::vector<int> kNone;
  const auto it = entity_physical_tags.find({e.entity_dim, e.entity_tag});
  return it == entity_physical_tags.end() ? kNone : it->second;
}

std::string MshFile::PhysicalName(int dim, int tag) const {
  for (const auto& p : physical_names) {
    if (p.dim == dim && p.tag == tag) return p.name;
  }
  return "";
}

MshFile ReadMshString(const std::string& text, const std::string& file) {
  MshFile m;
  m.file = file;
  LineCursor c(text, file);
  bool have_format = false, have_nodes = false, have_elements = false;
  std::string line;
  while (c.Next(&line)) {
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    if (line[0] != '$') c.Fail("expected a section ($Name), got '" + line + "'");
    const std::string section = line.substr(1);
    if (!have_format && section != "MeshFormat") c.Fail("not an MSH file: $MeshFormat must come first");
    if (section == "MeshFormat") {
      ReadMeshFormat(c);
      have_format = true;
    } else if (section == "PhysicalNames") {
      ReadPhysicalNames(c, &m);
    } else if (section == "Entities") {
      ReadEntities(c, &m);
    } else if (section == "PartitionedEntities") {
      c.Fail("partitioned meshes are not supported (save without partitions)");
    } else if (section == "Nodes") {
      ReadNodes(c, &m);
      have_nodes = true;
    } else if (section == "Elements") {
      ReadElements(c, &m);
      have_elements = true;
    } else {
      SkipSection(c, section);
    }
  }
  if (!have_format) throw ConfigError({file, 0, 0}, "empty file: not an MSH file");
  if (!have_nodes) throw ConfigError({file, 0, 0}, "no $Nodes section");
  if (!have_elements) throw ConfigError({file, 0, 0}, "no $Elements section");
  Validate(m);
  return m;
}

MshFile ReadMshFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError({path, 0, 0}, "cannot open mesh file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ReadMshString(ss.str(), path);
}

}  // namespace sedbridge::model

// src/mesh/gmsh_check.cpp: GmshStructureProblem (gmsh_check.hpp), the structure check of a user's gmsh file (formats
// 4.1 ASCII and binary, 2.2 ASCII) before PETSc 3.18's reader (src/dm/impls/plex/plexgmsh.c), which trusts the file.
// Linear in the file's size; memory: the file's text and one byte per node tag of the span the header declares.
#include "gmsh_check.hpp"
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rbc {

namespace {

struct Fault : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct NotChecked {}; // binary 2.2, which the tag check beside this one refuses (mesh_loader.cpp)

// Nodes of a gmsh element type that PETSc 3.18 reads (its GmshCellTable), its dimension; 0 for another type.
int TypeNodes(long long type, int *dim)
{
  auto sn1 = [](int p) { return p + 1; };
  auto sn2 = [](int p) { return (p + 1) * (p + 2) / 2; };
  auto sn3 = [](int p) { return (p + 1) * (p + 2) * (p + 3) / 6; };
  struct Row {
    int type, dim, nodes;
  };
  static const std::vector<Row> rows = [&] {
    std::vector<Row> r = {{15, 0, 1}, {16, 2, 8}, {17, 3, 20}};
    const int seg[] = {1, 8, 26, 27, 28, 62, 63, 64, 65, 66}, tri[] = {2, 9, 21, 23, 25, 42, 43, 44, 45, 46}, qua[] = {3, 10, 36, 37, 38, 47, 48, 49, 50, 51},
              tet[] = {4, 11, 29, 30, 31, 71, 72, 73, 74, 75}, hex[] = {5, 12, 92, 93, 94, 95, 96, 97, 98}, pri[] = {6, 13, 90, 91, 106, 107, 108, 109, 110},
              pyr[] = {7, 14, 118, 119, 120, 121, 122, 123, 124};
    for (int p = 1; p <= 10; ++p) {
      r.push_back({seg[p - 1], 1, sn1(p)});
      r.push_back({tri[p - 1], 2, sn2(p)});
      r.push_back({qua[p - 1], 2, sn1(p) * sn1(p)});
      r.push_back({tet[p - 1], 3, sn3(p)});
      if (p <= 9) {
        r.push_back({hex[p - 1], 3, sn1(p) * sn1(p) * sn1(p)});
        r.push_back({pri[p - 1], 3, sn2(p) * sn1(p)});
        r.push_back({pyr[p - 1], 3, (p + 1) * (p + 2) * (2 * p + 3) / 6});
      }
    }
    return r;
  }();
  for (const auto &r : rows)
    if (r.type == type) {
      *dim = r.dim;
      return r.nodes;
    }
  return 0;
}

// The file's whitespace-separated tokens, as PETSc's ASCII viewer reads them, with the line of each for the messages;
// in a binary file (format 4.1), a section's values are raw bytes instead (int: 4, size_t: the header's data size,
// double: 8; in the file's byte order, which its header's marker int says), between ASCII section names.
const long long kIntMaxT = 2147483647;
const size_t    kWordMax = 1000; // PETSc 3.18's reader reads a word into a 4096-byte buffer, unchecked; gmsh's are short

class Tokens {
public:
  explicit Tokens(std::string text) : t_(std::move(text)) {}
  bool AtEnd()
  {
    Skip();
    return p_ >= t_.size();
  }
  std::string_view Next(const char *what)
  {
    Skip();
    if (p_ >= t_.size()) Fail(std::string("the file ends where ") + what + " should follow");
    const size_t b = p_;
    while (p_ < t_.size() && !std::isspace((unsigned char)t_[p_])) ++p_;
    last_ = b;
    raw_  = false;
    for (size_t i = b; i < p_; ++i)
      if (IsControl(t_[i])) Fail(ControlByte(t_[i]));
    if (p_ - b > kWordMax) Fail("a word of " + std::to_string(p_ - b) + " characters where " + what + " should be (PETSc 3.18's reader reads words into a 4096-byte buffer, unchecked)");
    return std::string_view(t_).substr(b, p_ - b);
  }
  // Binary values from here on: int of 4 bytes, size_t of dsize (4 or 8); the byte order from the header's marker int
  // (1), which follows the header's line.
  void Binary(int dsize)
  {
    dsize_ = dsize;
    if (Raw(4, "the header's endianness marker (the int 1)") != 1) {
      big_ = true;
      p_ -= 4;
      if (Raw(4, "the header's endianness marker (the int 1)") != 1) Fail("the header's endianness marker is not the int 1 in either byte order (not a binary gmsh file, or a damaged one)");
    }
  }
  bool IsBinary() const { return dsize_ > 0 && !text_; }
  // A section of ASCII values in a binary file ($PhysicalNames), or the end of it.
  void TextSection(bool on) { text_ = on; }
  // An integer in [lo, hi]: a token, or in a binary file an int (4 bytes, signed) or, with size, a size_t (unsigned of
  // the data size); cast to a 32-bit PetscInt by the reader.
  long long Int(const char *what, long long lo, long long hi) { return Value(what, lo, hi, false); }
  long long Size(const char *what, long long lo, long long hi) { return Value(what, lo, hi, true); }
  // A header's count: at most what the rest of the file can hold (room: an upper bound from its size).
  long long Count(const char *what, long long room)
  {
    const long long v = Size(what, 0, kIntMaxT);
    if (v > room) Fail(std::string(what) + " is " + std::to_string(v) + ", more than the rest of the file can hold (" + std::to_string(room) + " at most)");
    return v;
  }
  void Real(const char *what) // any number, inf and nan included (the geometry check after the reader names those)
  {
    if (IsBinary()) {
      Raw(8, what);
      return;
    }
    const std::string tok(Next(what));
    char             *end = nullptr;
    (void)std::strtod(tok.c_str(), &end);
    if (tok.empty() || *end) Fail(std::string(what) + " is '" + Short(tok) + "', not a number");
  }
  void Expect(const char *word)
  {
    const std::string_view tok = Next(word);
    if (tok != word) Fail(std::string("'") + Short(std::string(tok)) + "' where " + word + " should be");
  }
  // The next section's name, past $Comments blocks (the reader skips them there); "" at the end of the file.
  std::string Section()
  {
    for (;;) {
      if (AtEnd()) return "";
      const std::string s(Next("a section"));
      if (s != "$Comments") return s;
      while (Next("$EndComments") != "$EndComments") {}
    }
  }
  // The rest of the line of the last token (the reader's physical name).
  std::string RestOfLine()
  {
    const size_t e = t_.find('\n', p_);
    std::string  r = t_.substr(p_, (e == std::string::npos ? t_.size() : e) - p_);
    for (char c : r)
      if (IsControl(c) && c != '\t' && c != '\r') Fail(ControlByte(c));
    p_ = e == std::string::npos ? t_.size() : e;
    return r;
  }
  // Characters left (a bound on the counts a header may declare).
  size_t Left() const { return t_.size() - p_; }
  size_t Mark() const { return p_; }
  void   Rewind(size_t at) { p_ = at; }
  [[noreturn]] void Fail(const std::string &why) const
  {
    const size_t at = last_ < t_.size() ? last_ : t_.size();
    if (dsize_ > 0) throw Fault(section_ + (section_.empty() ? "" : ", ") + "byte " + std::to_string(at) + ": " + why);
    size_t line = 1;
    for (size_t i = 0; i < at; ++i) line += t_[i] == '\n';
    throw Fault(section_ + (section_.empty() ? "" : ", ") + "line " + std::to_string(line) + ": " + why);
  }
  std::string section_;

private:
  static std::string Short(const std::string &s) { return s.size() > 40 ? s.substr(0, 40) + "..." : s; }
  // a byte no gmsh text holds (PETSc's reader: a NUL cut its words, then a segmentation fault or a hang)
  static bool        IsControl(char c) { return ((unsigned char)c < 0x20 && !std::isspace((unsigned char)c)) || c == 0x7f; }
  static std::string ControlByte(char c)
  {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x", (unsigned)(unsigned char)c);
    return std::string("a control byte (") + hex + ") in the text (a damaged file, or a binary one whose header says ASCII)";
  }
  void Skip()
  {
    while (p_ < t_.size() && std::isspace((unsigned char)t_[p_])) ++p_;
  }
  long long Value(const char *what, long long lo, long long hi, bool size)
  {
    long long   v;
    std::string shown;
    if (IsBinary()) {
      const unsigned long long u = Raw(size ? dsize_ : 4, what);
      if (size && u > (unsigned long long)hi) Fail(std::string(what) + " is " + std::to_string(u) + ", outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      v     = size ? (long long)u : (long long)(int32_t)(uint32_t)u;
      shown = std::to_string(v);
    } else {
      const std::string tok(Next(what));
      char             *end = nullptr;
      errno                 = 0;
      v                     = std::strtoll(tok.c_str(), &end, 10);
      if (tok.empty() || *end || errno) Fail(std::string(what) + " is '" + Short(tok) + "', not an integer");
      shown = tok;
    }
    if (v < lo || v > hi) Fail(std::string(what) + " is " + shown + ", outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  // n raw bytes as an unsigned value in the file's byte order. The first value after a section's name starts after
  // the one newline that ends the name's line, as gmsh writes it.
  unsigned long long Raw(int n, const char *what)
  {
    if (!raw_) {
      if (p_ >= t_.size() || t_[p_] != '\n') {
        last_ = p_;
        Fail(std::string("no newline before ") + what + " (binary data follows its section's name and one newline)");
      }
      ++p_;
      raw_ = true;
    }
    last_ = p_;
    if (t_.size() - p_ < (size_t)n) Fail(std::string("the file ends where ") + what + " should follow");
    unsigned long long v = 0;
    for (int i = 0; i < n; ++i) {
      const unsigned long long b = (unsigned char)t_[p_ + (size_t)i];
      v |= b << (8 * (big_ ? n - 1 - i : i));
    }
    p_ += (size_t)n;
    return v;
  }
  std::string t_;
  size_t      p_ = 0, last_ = 0;
  int         dsize_ = 0;     // > 0: a binary file
  bool        big_   = false; // its values are big-endian
  bool        raw_   = false; // the last thing read was raw bytes (else a token: a newline precedes the next raw value)
  bool        text_  = false; // an ASCII section of a binary file
};

const long long kIntMax = kIntMaxT; // the reader's int and 32-bit PetscInt

// The node tags a file defines: one flag per tag of [lo, hi], the span bounded so that neither this check nor the
// reader (which allocates an int per tag of the span) takes memory out of proportion to the mesh.
class NodeTags {
public:
  void Span(Tokens &tk, long long lo, long long hi, long long count)
  {
    if (count == 0) return;
    if (lo < 1 || hi < lo) tk.Fail("the node tags' range [" + std::to_string(lo) + ", " + std::to_string(hi) + "] is not a range of tags >= 1");
    const long long span = hi - lo + 1, limit = 8 * count + 1000000;
    if (span > limit)
      tk.Fail("the node tags span " + std::to_string(lo) + " to " + std::to_string(hi) + " for " + std::to_string(count) +
              " nodes: PETSc 3.18's reader allocates the whole span (more than 8 tags a node and 1e6 here); renumber the nodes contiguously (gmsh does so when it meshes, Mesh.Renumber = 1)");
    lo_ = lo;
    defined_.assign((size_t)span, 0);
  }
  void Define(Tokens &tk, long long tag)
  {
    if (tag < lo_ || tag - lo_ >= (long long)defined_.size()) tk.Fail("node tag " + std::to_string(tag) + " lies outside the range the header declares");
    char &d = defined_[(size_t)(tag - lo_)];
    if (d) tk.Fail("node tag " + std::to_string(tag) + " is defined twice");
    d = 1;
  }
  bool Known(long long tag) const { return tag >= lo_ && tag - lo_ < (long long)defined_.size() && defined_[(size_t)(tag - lo_)]; }

private:
  long long         lo_ = 1;
  std::vector<char> defined_;
};

void PhysicalNames(Tokens &tk)
{
  tk.section_           = "$PhysicalNames";
  const long long count = tk.Count("the number of physical names", (long long)tk.Left() / 4);
  for (long long i = 0; i < count; ++i) {
    tk.Int("a physical name's dimension", 0, 3);
    tk.Int("a physical tag", -kIntMax, kIntMax);
    const std::string rest = tk.RestOfLine();
    const size_t      a = rest.find('"'), b = rest.rfind('"');
    if (a == std::string::npos || b == a) tk.Fail("physical name " + std::to_string(i + 1) + " is not in double quotes");
    if (rest.find_first_not_of(" \t\r") != a || rest.find_first_not_of(" \t\r", b + 1) != std::string::npos) tk.Fail("physical name " + std::to_string(i + 1) + ": text outside its double quotes");
    const std::string name = rest.substr(a + 1, b - a - 1);
    if (name.empty() || name.size() > 127) tk.Fail("physical name " + std::to_string(i + 1) + " has " + std::to_string(name.size()) + " characters (1 to 127: gmsh's limit, and PETSc 3.18's reader's buffer)");
    if (name.find_first_of("\":") != std::string::npos) tk.Fail("physical name '" + name + "' holds a '\"' or ':' (PETSc 3.18's reader cuts a name at a ':', or reads past it): rename the group");
  }
  tk.Expect("$EndPhysicalNames");
}

void Entities41(Tokens &tk, std::set<long long> entities[4])
{
  tk.section_ = "$Entities";
  long long count[4];
  for (auto &c : count) c = tk.Count("an entity count", (long long)tk.Left() / 6);
  for (int dim = 0; dim < 4; ++dim)
    for (long long i = 0; i < count[dim]; ++i) {
      const long long tag = tk.Int("an entity tag", -kIntMax, kIntMax);
      if (!entities[dim].insert(tag).second) tk.Fail("entity " + std::to_string(tag) + " of dimension " + std::to_string(dim) + " is defined twice");
      for (int k = 0; k < (dim ? 6 : 3); ++k) tk.Real("a bounding box coordinate");
      const long long nphys = tk.Count("an entity's number of physical tags", (long long)tk.Left() / 2);
      if (nphys > 16) tk.Fail("entity " + std::to_string(tag) + " of dimension " + std::to_string(dim) + " is in " + std::to_string(nphys) + " physical groups (PETSc 3.18's reader takes 16 at most)");
      for (long long k = 0; k < nphys; ++k) tk.Int("a physical tag", -kIntMax, kIntMax);
      if (dim == 0) continue;
      const long long nb = tk.Count("an entity's number of bounding entities", (long long)tk.Left() / 2);
      for (long long k = 0; k < nb; ++k) tk.Int("a bounding entity tag", -kIntMax, kIntMax);
    }
  tk.Expect("$EndEntities");
}

void Nodes41(Tokens &tk, const std::set<long long> entities[4], NodeTags *tags)
{
  tk.section_           = "$Nodes";
  const long long nb    = tk.Count("the number of node blocks", (long long)tk.Left() / 8);
  const long long nn    = tk.Count("the number of nodes", (long long)tk.Left() / 8);
  const long long lo    = tk.Size("the smallest node tag", 0, kIntMax);
  const long long hi    = tk.Size("the largest node tag", 0, kIntMax);
  long long       total = 0;
  tags->Span(tk, lo, hi, nn);
  for (long long b = 0; b < nb; ++b) {
    const long long dim = tk.Int("a node block's entity dimension", 0, 3), eid = tk.Int("a node block's entity tag", -kIntMax, kIntMax);
    if (!entities[dim].count(eid)) tk.Fail("node block " + std::to_string(b + 1) + " names entity " + std::to_string(eid) + " of dimension " + std::to_string(dim) + ", which $Entities does not define");
    if (tk.Int("a node block's parametric flag", 0, 1)) tk.Fail("node block " + std::to_string(b + 1) + " has parametric coordinates, which PETSc 3.18's reader does not read (save the mesh without Mesh.SaveParametric)");
    const long long n = tk.Size("a node block's node count", 0, kIntMax);
    if (n > nn - total) tk.Fail("node block " + std::to_string(b + 1) + " holds " + std::to_string(n) + " nodes, more than the " + std::to_string(nn - total) + " the header's count of " + std::to_string(nn) + " leaves");
    for (long long k = 0; k < n; ++k) tags->Define(tk, tk.Size("a node tag", 1, kIntMax));
    for (long long k = 0; k < 3 * n; ++k) tk.Real("a node coordinate");
    total += n;
  }
  if (total != nn) tk.Fail("the node blocks hold " + std::to_string(total) + " nodes; the header says " + std::to_string(nn));
  tk.Expect("$EndNodes");
}

std::string UndefinedNode(long long element, long long node)
{
  return "element " + std::to_string(element) + " uses node " + std::to_string(node) + ", which the file does not define (a corrupt or hand-edited mesh)";
}

// "" or the undefined-node message (said without the section: the words of the check this one replaced)
std::string Elements41(Tokens &tk, const std::set<long long> entities[4], const NodeTags &tags)
{
  tk.section_        = "$Elements";
  const long long nb = tk.Count("the number of element blocks", (long long)tk.Left() / 8);
  const long long ne = tk.Count("the number of elements", (long long)tk.Left() / 4);
  tk.Size("the smallest element tag", 0, kIntMax);
  tk.Size("the largest element tag", 0, kIntMax);
  long long total = 0;
  for (long long b = 0; b < nb; ++b) {
    const long long dim = tk.Int("an element block's entity dimension", 0, 3), eid = tk.Int("an element block's entity tag", -kIntMax, kIntMax);
    if (!entities[dim].count(eid)) tk.Fail("element block " + std::to_string(b + 1) + " names entity " + std::to_string(eid) + " of dimension " + std::to_string(dim) + ", which $Entities does not define");
    const long long type = tk.Int("an element type", 0, kIntMax);
    int             tdim = -1;
    const int       nn   = TypeNodes(type, &tdim);
    if (!nn) tk.Fail("element type " + std::to_string(type) + " is not one PETSc 3.18's reader reads");
    if (tdim != dim) tk.Fail("element block " + std::to_string(b + 1) + " of dimension " + std::to_string(dim) + " holds elements of type " + std::to_string(type) + ", of dimension " + std::to_string(tdim));
    const long long n = tk.Size("an element block's element count", 0, kIntMax);
    if (n > ne - total) tk.Fail("element block " + std::to_string(b + 1) + " holds " + std::to_string(n) + " elements, more than the " + std::to_string(ne - total) + " the header's count of " + std::to_string(ne) + " leaves");
    for (long long k = 0; k < n; ++k) {
      const long long id = tk.Size("an element tag", 0, kIntMax);
      for (int j = 0; j < nn; ++j) {
        const long long node = tk.Size("an element's node tag", 0, kIntMax);
        if (!tags.Known(node)) return UndefinedNode(id, node);
      }
    }
    total += n;
  }
  if (total != ne) tk.Fail("the element blocks hold " + std::to_string(total) + " elements; the header says " + std::to_string(ne));
  tk.Expect("$EndElements");
  return "";
}

void Nodes22(Tokens &tk, NodeTags *tags)
{
  tk.section_        = "$Nodes";
  const long long nn = tk.Count("the number of nodes", (long long)tk.Left() / 8);
  // the tags first (their span decides the flags' size), then the same tokens again
  const size_t first = tk.Mark();
  long long    lo = kIntMax, hi = 0;
  for (long long k = 0; k < nn; ++k) {
    const long long t = tk.Int("a node tag", 1, kIntMax);
    lo                = std::min(lo, t);
    hi                = std::max(hi, t);
    for (int d = 0; d < 3; ++d) tk.Real("a node coordinate");
  }
  tags->Span(tk, lo, hi, nn);
  tk.Rewind(first);
  for (long long k = 0; k < nn; ++k) {
    tags->Define(tk, tk.Int("a node tag", 1, kIntMax));
    for (int d = 0; d < 3; ++d) tk.Next("a node coordinate");
  }
  tk.Expect("$EndNodes");
}

std::string Elements22(Tokens &tk, const NodeTags &tags)
{
  tk.section_        = "$Elements";
  const long long ne = tk.Count("the number of elements", (long long)tk.Left() / 8);
  for (long long e = 0; e < ne; ++e) {
    const long long id = tk.Int("an element tag", 0, kIntMax), type = tk.Int("an element type", 0, kIntMax);
    int             tdim = -1;
    const int       nn   = TypeNodes(type, &tdim);
    if (!nn) tk.Fail("element " + std::to_string(id) + " has type " + std::to_string(type) + ", not one PETSc 3.18's reader reads");
    const long long ntags = tk.Int("an element's number of tags", 0, kIntMax);
    if (ntags > 64) tk.Fail("element " + std::to_string(id) + " has " + std::to_string(ntags) + " tags (gmsh writes 2 to 4; PETSc 3.18's reader's buffer takes about 1000 tags and nodes)");
    for (long long k = 0; k < ntags; ++k) tk.Int("an element tag value", -kIntMax, kIntMax);
    for (int j = 0; j < nn; ++j) {
      const long long node = tk.Int("an element's node tag", 0, kIntMax);
      if (!tags.Known(node)) return UndefinedNode(id, node);
    }
  }
  tk.Expect("$EndElements");
  return "";
}

} // namespace

std::string GmshStructureProblem(const std::string &path)
{
  std::ifstream f(path, std::ios::binary);
  if (!f) return ""; // (the reader says it cannot open it)
  std::string text;
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  if (size > 0) {
    text.resize((size_t)size);
    f.seekg(0);
    f.read(&text[0], size);
    text.resize((size_t)f.gcount());
  }
  Tokens tk(std::move(text));
  try {
    const std::string first = tk.Section();
    if (first.empty()) return "the file is empty (or holds only white space)";
    if (first != "$MeshFormat") tk.Fail("'" + first.substr(0, 40) + "' where the first section, $MeshFormat, should be: not a gmsh file");
    tk.section_ = "$MeshFormat";
    const std::string ver(tk.Next("the format version"));
    const std::string type(tk.Next("the file type"));
    const std::string dsize(tk.Next("the data size"));
    const bool        v41 = ver == "4.1", v22 = ver == "2.2";
    if (!v41 && !v22)
      tk.Fail("the format version is '" + ver.substr(0, 40) + "': rbcontact reads gmsh files of format 4.1 (gmsh's default) or 2.2 (PETSc 3.18's reader mishandles the others, and an unchecked file can crash it); re-save it with gmsh -format msh41");
    if (type != "0" && type != "1") tk.Fail("the file type is '" + type.substr(0, 40) + "', not 0 (ASCII) or 1 (binary)");
    if (dsize != "8" && !(v41 && dsize == "4")) tk.Fail("the data size is '" + dsize.substr(0, 40) + "', not " + (v41 ? "8 or 4" : "8"));
    if (type == "1") {
      if (v22) throw NotChecked(); // binary 2.2: refused by the tag check beside this one (mesh_loader.cpp)
      tk.Binary(dsize == "8" ? 8 : 4);
    }
    tk.Expect("$EndMeshFormat");
    std::set<long long> entities[4];
    NodeTags            tags;
    tk.section_   = "after $EndMeshFormat";
    std::string s = tk.Section();
    if (s == "$PhysicalNames") {
      tk.TextSection(true); // (ASCII in a binary file too)
      PhysicalNames(tk);
      tk.TextSection(false);
      tk.section_ = "after $EndPhysicalNames";
      s           = tk.Section();
    }
    if (v41) {
      tk.section_ = "before $Entities";
      if (s != "$Entities") tk.Fail("'" + s + "' where $Entities should be (PETSc 3.18's reader needs it in format 4.1)");
      Entities41(tk, entities);
      tk.section_ = "after $EndEntities";
      s           = tk.Section();
    }
    tk.section_ = "before $Nodes";
    if (s != "$Nodes") tk.Fail("'" + s + "' where $Nodes should be");
    if (v41) Nodes41(tk, entities, &tags);
    else Nodes22(tk, &tags);
    tk.section_ = "after $EndNodes";
    s           = tk.Section();
    if (s != "$Elements") tk.Fail("'" + s + "' where $Elements should be");
    const std::string undefined = v41 ? Elements41(tk, entities, tags) : Elements22(tk, tags);
    if (!undefined.empty()) return undefined;
    tk.section_ = "after $EndElements";
    if (tk.Section() == "$Periodic") tk.Fail("a $Periodic section (gmsh Periodic constraints): PETSc 3.18's reader follows its node links unchecked, and contact bodies are not periodic: remove the Periodic constraints");
  } catch (const Fault &e) {
    return e.what();
  } catch (const NotChecked &) {
    return "";
  }
  return "";
}

} // namespace rbc

// tests/test_gmsh_check.cpp: rbc::GmshStructureProblem (src/mesh/gmsh_check.hpp), the check of a user's ASCII gmsh
// file before PETSc 3.18's reader. A sound two-triangle mesh in formats 4.1 and 2.2 passes; each fault the fuzzing
// audit of 2026-12-02 found (docs/bad_input.md: a physical name with a ':' before its quotes or of 300 characters,
// counts that disagree with the blocks, an undefined entity or a dimension beyond 3, an element type of another
// dimension, sparse node tags, a 2.2 element with 1200 or 2e12 tags, a count of 2e9 names), and a truncated file, a
// repeated node tag, an undefined node and a $Periodic section, gives its message. The same for binary 4.1 (sound in
// both byte orders and data sizes; a short count, an undefined node, a cut file, a bad marker), and everything the
// reader was not written for is refused: format 4.0 or 2.6, an odd data size or file type, NUL bytes, an unterminated
// $Comments block, a word of 5000 characters, not a gmsh file, an empty file. Binary 2.2 is left to the tag check
// beside this one (""). No PETSc: the check runs on rank 0 before the reader.
#include "../src/mesh/gmsh_check.hpp"
#include <unistd.h>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

static int failures = 0;

static void Check(bool ok, const std::string &what)
{
  if (!ok) ++failures;
  std::printf("  %-5s %s\n", ok ? "ok" : "FAIL", what.c_str());
}

// Two triangles on the unit square, body "body", boundary "bottom", in format 4.1.
static const std::string kMesh41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
                                   "$PhysicalNames\n2\n1 11 \"bottom\"\n2 1 \"body\"\n$EndPhysicalNames\n"
                                   "$Entities\n4 1 1 0\n"
                                   "1 0 0 0 0\n2 1 0 0 0\n3 1 1 0 0\n4 0 1 0 0\n"
                                   "1 0 0 0 1 0 0 1 11 2 1 -2\n"
                                   "1 0 0 0 1 1 0 1 1 1 1\n"
                                   "$EndEntities\n"
                                   "$Nodes\n2 4 1 4\n0 1 0 1\n1\n0 0 0\n2 1 0 3\n2\n3\n4\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n"
                                   "$Elements\n2 3 1 3\n1 1 1 1\n1 1 2\n2 1 2 2\n2 1 2 3\n3 1 3 4\n$EndElements\n";
// The same in format 2.2.
static const std::string kMesh22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                   "$PhysicalNames\n2\n1 11 \"bottom\"\n2 1 \"body\"\n$EndPhysicalNames\n"
                                   "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n"
                                   "$Elements\n3\n1 1 2 11 1 1 2\n2 2 2 1 1 1 2 3\n3 2 2 1 1 1 3 4\n$EndElements\n";

static std::string Problem(const std::string &text)
{
  char path[] = "/tmp/rbc_gmsh_check_XXXXXX";
  int  fd     = mkstemp(path);
  if (fd < 0) return "cannot create a temporary file";
  close(fd);
  {
    std::ofstream f(path, std::ios::binary);
    f << text;
  }
  const std::string p = rbc::GmshStructureProblem(path);
  unlink(path);
  return p;
}

static std::string Replace(std::string s, const std::string &from, const std::string &to)
{
  const size_t at = s.find(from);
  if (at == std::string::npos) return "(the test's edit '" + from + "' found nothing)";
  return s.replace(at, from.size(), to);
}

// The two-triangle mesh of kMesh41 in binary format 4.1, as gmsh writes it: ASCII section names, the values of a
// section raw after its name's newline (int: 4 bytes, size_t: dsize, double: 8), in little- or big-endian byte order.
// edit changes it before it is written: nodes, the header's node count; node9, the last triangle's last node.
struct Bin41 {
  int  dsize = 8;
  bool big = false, node9 = false;
  long nodes = 4;
  std::string b;
  void Raw(unsigned long long v, int n)
  {
    for (int i = 0; i < n; ++i) b += (char)((v >> (8 * (big ? n - 1 - i : i))) & 0xff);
  }
  void I(long long v) { Raw((unsigned long long)v & 0xffffffffull, 4); }
  void S(unsigned long long v) { Raw(v, dsize); }
  void D(double v)
  {
    unsigned long long u;
    std::memcpy(&u, &v, 8);
    Raw(u, 8);
  }
  std::string Text()
  {
    b = "$MeshFormat\n4.1 1 " + std::to_string(dsize) + "\n";
    I(1);
    b += "\n$EndMeshFormat\n$PhysicalNames\n2\n1 11 \"bottom\"\n2 1 \"body\"\n$EndPhysicalNames\n$Entities\n";
    S(4), S(1), S(1), S(0);
    const double pt[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i < 4; ++i) I(i + 1), D(pt[i][0]), D(pt[i][1]), D(0), S(0);
    I(1), D(0), D(0), D(0), D(1), D(0), D(0), S(1), I(11), S(2), I(1), I(-2); // curve 1: bottom
    I(1), D(0), D(0), D(0), D(1), D(1), D(0), S(1), I(1), S(1), I(1);         // surface 1: body
    b += "\n$EndEntities\n$Nodes\n";
    S(2), S(nodes), S(1), S(4);
    I(0), I(1), I(0), S(1), S(1), D(0), D(0), D(0);
    I(2), I(1), I(0), S(3), S(2), S(3), S(4), D(1), D(0), D(0), D(1), D(1), D(0), D(0), D(1), D(0);
    b += "\n$EndNodes\n$Elements\n";
    S(2), S(3), S(1), S(3);
    I(1), I(1), I(1), S(1), S(1), S(1), S(2);
    I(2), I(1), I(2), S(2), S(2), S(1), S(2), S(3), S(3), S(1), S(3), S(node9 ? 9 : 4);
    b += "\n$EndElements\n";
    return b;
  }
};

static void Expect(const std::string &what, const std::string &text, const std::string &words)
{
  const std::string p = Problem(text);
  Check(words.empty() ? p.empty() : p.find(words) != std::string::npos, what + ": " + (p.empty() ? "accepted" : p));
}

int main(int argc, char **argv)
{
  // files given: gmsh's own output (tests/elasticity.cmake meshes every meshes/*.geo in formats 4.1 and 2.2), all accepted
  for (int i = 1; i < argc; ++i) {
    const std::string p = rbc::GmshStructureProblem(argv[i]);
    Check(p.empty(), std::string("gmsh's own ") + argv[i] + ": " + (p.empty() ? "accepted" : p));
  }
  Expect("format 4.1, sound", kMesh41, "");
  Expect("format 2.2, sound", kMesh22, "");
  Expect("4.1 with a $Comments block before $Nodes", Replace(kMesh41, "$Nodes\n", "$Comments\nwritten by hand\n$EndComments\n$Nodes\n"), "");
  // physical names (PETSc: a ':' before the quotes gave a negative length, a segmentation fault; 300 characters
  // overflowed its 130-byte buffer)
  Expect("a ':' before a name's quotes", Replace(kMesh41, "2 1 \"body\"", "2 1 :x\"body\""), "$PhysicalNames, line 7: physical name 2: text outside its double quotes");
  Expect("a name of 300 characters", Replace(kMesh41, "\"bottom\"", "\"" + std::string(300, 'b') + "\""), "physical name 1 has 300 characters (1 to 127");
  Expect("a ':' inside a name", Replace(kMesh41, "\"bottom\"", "\"bot:tom\""), "physical name 'bot:tom' holds a '\"' or ':'");
  Expect("2e9 physical names (2.2: 2e9 failed reads)", Replace(kMesh22, "$PhysicalNames\n2\n", "$PhysicalNames\n2000000000\n"), "the number of physical names is 2000000000, more than the rest of the file can hold");
  // counts against blocks (PETSc: an overrun, "malloc(): invalid size", then a hang)
  Expect("4.1 nodes: the header says 3, the blocks hold 4", Replace(kMesh41, "$Nodes\n2 4 1 4", "$Nodes\n2 3 1 4"), "node block 2 holds 3 nodes, more than the 2 the header's count of 3 leaves");
  Expect("4.1 nodes: the header says 5, the blocks hold 4", Replace(kMesh41, "$Nodes\n2 4 1 4", "$Nodes\n2 5 1 5"), "the node blocks hold 4 nodes; the header says 5");
  Expect("4.1 elements: the header says 2, the blocks hold 3", Replace(kMesh41, "$Elements\n2 3 1 3", "$Elements\n2 2 1 3"), "element block 2 holds 2 elements, more than the 1 the header's count of 2 leaves");
  // entities (PETSc: index -1 or dimension 9 of its arrays, segmentation faults)
  Expect("a node block of an undefined entity", Replace(kMesh41, "0 1 0 1\n1\n", "0 77 0 1\n1\n"), "node block 1 names entity 77 of dimension 0, which $Entities does not define");
  Expect("an element block of dimension 9", Replace(kMesh41, "2 1 2 2\n", "9 1 2 2\n"), "an element block's entity dimension is 9, outside [0, 3]");
  Expect("an element block of an undefined entity", Replace(kMesh41, "2 1 2 2\n", "2 5 2 2\n"), "element block 2 names entity 5 of dimension 2, which $Entities does not define");
  Expect("triangles in a block of dimension 1", Replace(kMesh41, "1 1 1 1\n1 1 2\n", "1 1 2 1\n1 1 2 3\n"), "element block 1 of dimension 1 holds elements of type 2, of dimension 2");
  Expect("an element type PETSc does not read", Replace(kMesh41, "2 1 2 2\n", "2 1 99 2\n"), "element type 99 is not one PETSc 3.18's reader reads");
  Expect("an entity in 17 physical groups", Replace(kMesh41, "1 0 0 0 1 1 0 1 1 1 1\n", "1 0 0 0 1 1 0 17 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 1 1\n"), "is in 17 physical groups (PETSc 3.18's reader takes 16 at most)");
  Expect("an entity defined twice", Replace(kMesh41, "2 1 0 0 0\n", "1 1 0 0 0\n"), "entity 1 of dimension 0 is defined twice");
  // node tags (PETSc: the span 1 to 3e8 allocated, 1.2 GB for 5 nodes; a repeated tag; an undefined node indexed)
  Expect("sparse node tags", Replace(Replace(kMesh41, "2 4 1 4", "2 4 1 300000000"), "2\n3\n4\n1 0 0", "2\n3\n300000000\n1 0 0"), "the node tags span 1 to 300000000 for 4 nodes");
  Expect("a node tag twice", Replace(kMesh41, "2\n3\n4\n1 0 0", "2\n3\n3\n1 0 0"), "node tag 3 is defined twice");
  Expect("an element on an undefined node (4.1)", Replace(kMesh41, "3 1 3 4\n", "3 1 3 9\n"), "element 3 uses node 9, which the file does not define (a corrupt or hand-edited mesh)");
  Expect("an element on an undefined node (2.2)", Replace(kMesh22, "3 2 2 1 1 1 3 4\n", "3 2 2 1 1 1 3 99999\n"), "element 3 uses node 99999, which the file does not define");
  Expect("2.2 sparse node tags", Replace(Replace(kMesh22, "4 0 1 0\n$EndNodes", "400000000 0 1 0\n$EndNodes"), "1 3 4\n$End", "1 3 400000000\n$End"), "the node tags span 1 to 400000000 for 4 nodes");
  // 2.2 tags (PETSc: 1200 tags overflowed its 1005-int buffer; 2e12 looped for ever in the tag check before this one)
  Expect("a 2.2 element with 1200 tags", Replace(kMesh22, "1 1 2 11 1 1 2\n", "1 1 1200 11 1 1 2\n"), "element 1 has 1200 tags (gmsh writes 2 to 4");
  Expect("a 2.2 element with 2e12 tags", Replace(kMesh22, "1 1 2 11 1 1 2\n", "1 1 2488959697294 11 1 1 2\n"), "an element's number of tags is 2488959697294, outside [0, 2147483647]");
  // the rest
  Expect("a file that ends inside $Nodes", kMesh41.substr(0, kMesh41.find("3\n4\n1 0 0")), "$Nodes, line");
  Expect("a non-number where a coordinate is", Replace(kMesh22, "2 1 0 0\n", "2 1 x 0\n"), "a node coordinate is 'x', not a number");
  Expect("inf coordinates are left to the geometry check", Replace(kMesh22, "2 1 0 0\n", "2 inf 0 0\n"), "");
  Expect("a $Periodic section", kMesh41 + "$Periodic\n0\n$EndPeriodic\n", "a $Periodic section (gmsh Periodic constraints)");
  Expect("parametric nodes", Replace(kMesh41, "0 1 0 1\n1\n", "0 1 1 1\n1\n"), "has parametric coordinates");
  // binary 4.1 (PETSc: a short node count, an abort then a hang; an undefined node, a segmentation fault)
  {
    Bin41 sound, big, d4, short_count, undefined;
    big.big = true, d4.dsize = 4, short_count.nodes = 3, undefined.node9 = true;
    Expect("binary 4.1, sound", sound.Text(), "");
    Expect("binary 4.1, big-endian", big.Text(), "");
    Expect("binary 4.1, data size 4", d4.Text(), "");
    Expect("binary 4.1: the header says 3 nodes, the blocks hold 4", short_count.Text(), "$Nodes, byte ");
    Expect("binary 4.1: ... and names the fault", short_count.Text(), "node block 2 holds 3 nodes, more than the 2 the header's count of 3 leaves");
    Expect("binary 4.1: an element on an undefined node", undefined.Text(), "element 3 uses node 9, which the file does not define");
    const std::string t = sound.Text();
    Expect("binary 4.1 cut inside $Elements", t.substr(0, t.find("$EndElements") - 20), "$Elements, byte");
    Expect("binary 4.1 with a marker that is not 1", Replace(t, std::string("\n\x01\0\0\0\n", 6), std::string("\n\x02\0\0\0\n", 6)), "the header's endianness marker is not the int 1 in either byte order");
    Expect("binary 4.1 with a space after a section's name", Replace(t, "$Nodes\n", "$Nodes \n"), "no newline before the number of node blocks");
    Expect("ASCII 4.1 read as binary (the header says 1)", Replace(kMesh41, "4.1 0 8", "4.1 1 8"), "the header's endianness marker is not the int 1");
  }
  // everything else is refused: PETSc's reader was not written for it (each a crash or a hang in the fuzzing audit)
  Expect("binary 2.2: refused by the tag check beside this one", Replace(kMesh22, "2.2 0 8", "2.2 1 8"), "");
  Expect("format 4.0", Replace(kMesh41, "4.1 0 8", "4.0 0 8"), "$MeshFormat, line 2: the format version is '4.0': rbcontact reads gmsh files of format 4.1 (gmsh's default) or 2.2");
  Expect("format 2.6", Replace(kMesh22, "2.2 0 8", "2.6 0 8"), "the format version is '2.6'");
  Expect("a data size of 0+8", Replace(kMesh41, "4.1 0 8", "4.1 0 0+8"), "the data size is '0+8', not 8 or 4");
  Expect("a file type of 2", Replace(kMesh41, "4.1 0 8", "4.1 2 8"), "the file type is '2', not 0 (ASCII) or 1 (binary)");
  Expect("a NUL byte before $MeshFormat", std::string("\0", 1) + kMesh41, "line 1: a control byte (0x00) in the text");
  Expect("a NUL byte in the version line", Replace(kMesh41, "4.1 0 8", std::string("4.1\0 0 8", 7)), "$MeshFormat, line 2: a control byte (0x00)");
  Expect("a NUL byte in a physical name", Replace(kMesh41, "\"body\"", std::string("\"bo\0dy\"", 7)), "$PhysicalNames, line 7: a control byte (0x00)");
  Expect("an unterminated $Comments block", "$Comments\nhello\n", "the file ends where $EndComments should follow");
  Expect("a word of 5000 characters", Replace(kMesh41, "$Nodes\n", "$Comments\n" + std::string(5000, 'w') + "\n$EndComments\n$Nodes\n"), "after $EndEntities, line 19: a word of 5000 characters where $EndComments should be");
  Expect("not a gmsh file", "hello\n", "line 1: 'hello' where the first section, $MeshFormat, should be: not a gmsh file");
  Expect("an empty file", "", "the file is empty");
  std::printf("%d failure(s)\n", failures);
  return failures ? 1 : 0;
}

// src/mesh/gmsh_check.hpp: the structure check of a user's gmsh file before PETSc 3.18's reader, which MeshLoad calls
// only for a file this check has read and found sound. That reader trusts every count, tag and reference of the file:
// a section holding more nodes than its header says overruns its arrays (an abort, then a hang), a block naming an
// entity the file does not define or a dimension beyond 3 indexes out of bounds (segmentation faults), a physical name
// longer than 127 characters or with a ':' before its quotes overflows a buffer, a 2.2 element with 2e9 tags loops for
// ever, sparse node tags make it allocate their whole span, a NUL byte or a format it was not written for (4.0, 2.6)
// crashes it (found by fuzzing, docs/bad_input.md). The check reads the file as the reader does (whitespace-separated
// tokens; raw values in binary 4.1) and names the first thing the reader would mishandle.
#pragma once
#include <string>

namespace rbc {

// "" when the gmsh file at path (format 4.1 ASCII or binary, 2.2 ASCII) holds nothing PETSc 3.18's reader
// mishandles, or when it is in binary format 2.2 (refused by the tag check beside this one, mesh_loader.cpp).
// Otherwise the first fault, with its section and line (byte offset in a binary file): "$Nodes, line 31: node block 2
// names entity 77 of dimension 0, which $Entities does not define". Everything else is refused too, since the reader
// crashed on it (fuzzing, docs/bad_input.md): not a gmsh file, an empty one, a format version other than 4.1 and 2.2
// (4.0, 2.6), a data size other than 8 (or 4 in 4.1), a control byte (a NUL) in the text, a word of more than 1000
// characters. An element naming an undefined node is said as "element 12 uses node 99999, which the file does not
// define (a corrupt or hand-edited mesh)".
std::string GmshStructureProblem(const std::string &path);

} // namespace rbc

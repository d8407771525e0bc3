// src/mesh/gmsh_check.hpp: the structure check of a user's gmsh file before PETSc 3.18's reader. That reader trusts
// every count, tag and reference of the file: a section holding more nodes than its header says overruns its arrays
// (an abort, then a hang), a block naming an entity the file does not define or a dimension beyond 3 indexes out of
// bounds (segmentation faults), a physical name longer than 127 characters or with a ':' before its quotes overflows a
// buffer, a 2.2 element with 2e9 tags loops for ever, sparse node tags make it allocate their whole span (found by
// fuzzing, docs/bad_input.md). The check reads the file as the reader does (whitespace-separated tokens) and
// names the first thing the reader would mishandle.
#pragma once
#include <string>

namespace rbc {

// "" when the ASCII gmsh file at path (format 4.1 or 2.2) holds nothing PETSc 3.18's reader mishandles, or when the
// file is not of a kind checked here (binary, format 4.0, not a gmsh file: PETSc's reader, or the tag checks beside
// this one, say what is wrong). Otherwise the first fault, with its section and line ("$Nodes, line 31: node block 2
// names entity 77 of dimension 0, which $Entities does not define"). An element naming an undefined node is said as
// "element 12 uses node 99999, which the file does not define (a corrupt or hand-edited mesh)".
std::string GmshStructureProblem(const std::string &path);

} // namespace rbc

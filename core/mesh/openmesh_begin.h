// Included right before a block of OpenMesh headers, with openmesh_end.h right
// after it (no include guard: it is meant to be included more than once).
//
// OpenMesh's header code is compiled as Debian compiles libOpenMeshCore,
// without its assert() checks, also in the builds that keep assert() on
// (the sanitizer builds): OpenMesh checks every property access by comparing
// two type names as freshly built std::string objects, which made a
// sanitized mesh decimation spend most of its time allocating. The bounds
// of those accesses stay checked in the sanitizer builds by the standard
// library's own assertions (_GLIBCXX_ASSERTIONS, cmake/MmmTargets.cmake).
// Every OpenMesh include of mmm goes through this pair, so all translation
// units see the same OpenMesh inline code.

#ifndef NDEBUG
#define NDEBUG
#define MMM_OPENMESH_RESTORE_ASSERT
#endif
#include <cassert>

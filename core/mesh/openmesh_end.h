// Closes a block of OpenMesh headers opened by openmesh_begin.h: assert()
// checks mmm's own code again in the builds that keep it.

#ifdef MMM_OPENMESH_RESTORE_ASSERT
#undef NDEBUG
#undef MMM_OPENMESH_RESTORE_ASSERT
#endif
#include <cassert>

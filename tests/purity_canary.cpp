// Deliberately impure: the purity check must reject this library (ctest core_purity_detects_heap expects failure).
#include <new>

int* purity_canary_allocate() { return new int(42); }

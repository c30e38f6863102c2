/* fuzz_obj.c -- libFuzzer harness for the strict OBJ reader. */
#include "fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_mesh(data, size, "obj", mesh_load_obj); }

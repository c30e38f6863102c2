/* fuzz_ply.c -- libFuzzer harness for the PLY reader (ascii and binary). */
#include "fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_mesh(data, size, "ply", mesh_load_ply); }

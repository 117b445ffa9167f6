#include <gtest/gtest.h>

#include "core/runtime/allocator.h"
#include "core/runtime/blas.h"

int main(int argc, char** argv) {
  bimart::runtime::ensure_blas_kernel(argc, argv);
  bimart::runtime::tune_allocator();
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

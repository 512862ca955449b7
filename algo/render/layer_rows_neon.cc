#include "algo/render/layer_rows.h"

namespace lb::layer_rows {
const Kernels* NeonKernels() { return nullptr; }
}  // namespace lb::layer_rows

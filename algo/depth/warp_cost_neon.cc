#include "algo/depth/data_term_kernels.h"

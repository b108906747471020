// Search engines over the radix heap: every grid connectivity and cost model, and CSR graphs.
#include "graph/search_instances.h"

VS_INSTANTIATE_SEARCH_ENGINES(vs::detail::RadixQueue)

// Search engines over the bucket queue (the default; also the two-thread full map): every grid connectivity and cost
// model, and CSR graphs.
#include "graph/search_instances.h"

VS_INSTANTIATE_SEARCH_ENGINES(vs::detail::BucketQueue)

// Placeholder: being written.
#include "asperity/statistics.hpp"

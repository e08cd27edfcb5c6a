#include "mesh/ReferencePolicy.h"

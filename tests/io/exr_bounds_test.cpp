// Issue 26 tests (being written).
#include "support/TestSupport.h"

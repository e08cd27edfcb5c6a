#include "io/OutputPaths.h"

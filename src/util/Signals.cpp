#include "util/Signals.h"

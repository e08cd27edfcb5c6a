#include "io/ImageHeader.h"

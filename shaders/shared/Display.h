// The display kernel's interface (viewer): bindings and push constants.
#ifndef VKRT_SHARED_DISPLAY_H
#define VKRT_SHARED_DISPLAY_H
#include "Interop.h"

VKRT_BEGIN_NAMESPACE

VKRT_CONSTANT(uint, DISPLAY_BINDING_ACCUMULATION, 0) // AccumPixel[] (read)
VKRT_CONSTANT(uint, DISPLAY_BINDING_OUTPUT, 1)       // rgba8 storage image (write)

// DisplayConstants::toneMapper
VKRT_CONSTANT(uint, TONE_MAP_CLAMP, 0)  // clamp to [0, 1]
VKRT_CONSTANT(uint, TONE_MAP_FILMIC, 1) // ACES filmic curve (Narkowicz 2015 fit)

struct DisplayConstants {
    float exposureScale; // 2^exposure
    uint width;
    uint height;
    uint toneMapper;
};

VKRT_END_NAMESPACE

#endif

// How the kernels declare and read the scene's read-only buffers.
//
//   VKRT_READ_BUFFER(BINDING_X, XBlock, X, xs)          declares the buffer;
//   #define xs VKRT_READ_ITEMS(BINDING_X, XBlock, xs)   names its records.
//
// Code then reads xs[i] either way. With VKRT_SCENE_ADDRESSES (render
// kernels on devices where it pays: render/Renderer.h, sceneAddressesPay)
// the records are read through the buffer's device address,
// SceneUniforms::bufferAddresses[BINDING_X], which the host fills for every
// buffer it binds (render/Renderer.cpp); otherwise (and in the test probes)
// through the storage-buffer descriptor, which stays bound either way.
//
// Why: lavapipe before Mesa 26 compiles a storage-buffer load whose offset
// differs between the lanes of a subgroup into a loop over the lanes, each
// with its bounds check, and a device-address load into one gather. A
// kernel with a few hundred such load sites spent most of its compile time
// on those loops (docs/performance.md, "Staged kernels").
//
// The scene arrays of the shape and light kinds and the materials
// (VKRT_SCENE_ARRAY, VKRT_SCENE_ITEMS) are uniform blocks in the
// uniform-scene variant (small scenes: a uniform load is a gather already)
// and read buffers otherwise.
#ifndef VKRT_SCENE_BUFFERS_GLSL
#define VKRT_SCENE_BUFFERS_GLSL

#ifdef VKRT_SCENE_ADDRESSES
#define VKRT_READ_BUFFER(binding_, Block, Type, name) \
    layout(buffer_reference, scalar, buffer_reference_align = 4) readonly buffer Block { Type items[]; };
#define VKRT_READ_ITEMS(binding_, Block, name) Block(u.bufferAddresses[binding_]).items
#else
#define VKRT_READ_BUFFER(binding_, Block, Type, name) \
    layout(scalar, binding = binding_) readonly buffer Block { Type name[]; };
// The name itself: a macro is not expanded again inside its own expansion.
#define VKRT_READ_ITEMS(binding_, Block, name) name
#endif

#ifndef VKRT_SCENE_ARRAY // the probes declare their records themselves
#ifdef VKRT_UNIFORM_SCENE
#define VKRT_SCENE_ARRAY(binding_, Block, Type, name, capacity) \
    layout(scalar, binding = binding_) uniform Block { Type name[capacity]; };
#define VKRT_SCENE_ITEMS(binding_, Block, name) name
#else
#define VKRT_SCENE_ARRAY(binding_, Block, Type, name, capacity) VKRT_READ_BUFFER(binding_, Block, Type, name)
#define VKRT_SCENE_ITEMS(binding_, Block, name) VKRT_READ_ITEMS(binding_, Block, name)
#endif
#endif

#endif

#ifndef VKRT_CAMERA_GLSL
#define VKRT_CAMERA_GLSL

// Pinhole camera at the origin (scene data is camera-relative). `subpixel` in
// [0,1)^2 picks the point inside the pixel; row 0 is the top of the image.
// The unnormalized direction reaches the plane one unit ahead (cameraForward
// is a unit vector; cameraRight and cameraUp are scaled to that plane).
vec3 pinholeDirection(uvec2 pixel, vec2 subpixel)
{
    vec2 film = (vec2(pixel) + subpixel) / vec2(u.width, u.height);
    vec2 ndc = vec2(2.0 * film.x - 1.0, 1.0 - 2.0 * film.y);
    return ndc.x * u.cameraRight + ndc.y * u.cameraUp + u.cameraForward;
}

// An orthographic camera (glTF's; kernels with VKRT_ORTHOGRAPHIC, chosen by
// RENDER_FLAG_ORTHOGRAPHIC so the uber kernel has both): parallel rays along
// cameraForward from the plane through the eye, cameraRight and cameraUp
// scaled to the view's half width and height in scene units.
Ray cameraRay(uvec2 pixel, vec2 subpixel)
{
#ifdef VKRT_ORTHOGRAPHIC
    if ((u.flags & RENDER_FLAG_ORTHOGRAPHIC) != 0u) {
        vec2 film = (vec2(pixel) + subpixel) / vec2(u.width, u.height);
        vec2 ndc = vec2(2.0 * film.x - 1.0, 1.0 - 2.0 * film.y);
        return Ray(ndc.x * u.cameraRight + ndc.y * u.cameraUp, u.cameraForward);
    }
#endif
    return Ray(vec3(0.0), normalize(pinholeDirection(pixel, subpixel)));
}

#ifdef VKRT_THIN_LENS
#include "sampling.glsl"

// Thin lens (Mitsuba 3's `thinlens`, pbrt's PerspectiveCamera): the pinhole
// ray's point on the plane in focus, u.focusDistance ahead, is seen from a
// point `lens` in [0,1)^2 mapped to the lens disk of radius u.apertureRadius.
Ray thinLensRay(uvec2 pixel, vec2 subpixel, vec2 lens)
{
    vec3 focusPoint = pinholeDirection(pixel, subpixel) * u.focusDistance;
    vec2 disk = concentricDisk(lens) * u.apertureRadius;
    vec3 origin = disk.x * normalize(u.cameraRight) + disk.y * normalize(u.cameraUp);
    return Ray(origin, normalize(focusPoint - origin));
}
#endif

#endif

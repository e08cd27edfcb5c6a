#ifndef VKRT_CAMERA_GLSL
#define VKRT_CAMERA_GLSL

// Pinhole camera at the origin (scene data is camera-relative). `subpixel` in
// [0,1)^2 picks the point inside the pixel; row 0 is the top of the image.
Ray cameraRay(uvec2 pixel, vec2 subpixel)
{
    vec2 film = (vec2(pixel) + subpixel) / vec2(u.width, u.height);
    vec2 ndc = vec2(2.0 * film.x - 1.0, 1.0 - 2.0 * film.y);
    vec3 dir = ndc.x * u.cameraRight + ndc.y * u.cameraUp + u.cameraForward;
    return Ray(vec3(0.0), normalize(dir));
}

#endif

#pragma once
// GGX (Trowbridge-Reitz) microfacet distribution in double precision, in the local shading frame
// (normal +z): the definitions vkrt's GLSL BSDFs follow, used by the albedo tables and the reference
// BSDFs of the tests. alpha = roughness^2; anisotropic alphas along x and y.
#include <glm/vec3.hpp>

namespace vkrt {

/// GGX distribution with roughnesses ax (along x) and ay (along y).
struct Ggx {
    double ax = 1.0;
    double ay = 1.0;

    /// Normal distribution D(m) (1/sr of projected area; zero below the surface).
    double d(const glm::dvec3& m) const;
    /// Smith's Lambda(w) for a direction w.
    double lambda(const glm::dvec3& w) const;
    /// Smith's masking G1(w, m) = 1 / (1 + Lambda(w)), zero if w sees the back of m.
    double g1(const glm::dvec3& w, const glm::dvec3& m) const;
    /// Separable masking-shadowing G1(wo, m) * G1(wi, m) (Mitsuba 3's choice).
    double g(const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& m) const;
    /// Height-correlated masking-shadowing 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014, eq. 99), zero if
    /// either direction sees the back of m: glTF 2.0's (Appendix B, V_GGX), which the pbr material follows.
    double gCorrelated(const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& m) const;
    /// Density of visible normals seen from w (w.z > 0): G1(w, m) max(0, w.m) D(m) / w.z.
    double visibleNormalPdf(const glm::dvec3& w, const glm::dvec3& m) const;
    /// A visible normal seen from w (w.z > 0) for a point (t1, t2) of the unit disk (Heitz 2018, "Sampling
    /// the GGX Distribution of Visible Normals", JCGT 7(4)): points uniform on the disk give m ~ D_w.
    glm::dvec3 visibleNormalFromDisk(const glm::dvec3& w, double t1, double t2) const;
    /// A visible normal seen from w (w.z > 0) from two uniforms in [0, 1) (Heitz 2018, listing 1).
    glm::dvec3 sampleVisibleNormal(const glm::dvec3& w, double u1, double u2) const;
};

/// Mirror reflection of w about the unit normal m.
glm::dvec3 reflect(const glm::dvec3& w, const glm::dvec3& m);

} // namespace vkrt

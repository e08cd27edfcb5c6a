#pragma once
// Exact unpolarized Fresnel reflectance in double precision, shared by the
// microfacet albedo tables (renderer side) and the reference BSDFs (tests).
namespace vkrt {

/// Reflectance of a dielectric interface and the refracted cosine.
struct DielectricFresnel {
    double reflectance = 1.0; ///< 1 under total internal reflection
    double cosT = 0.0;        ///< |cos| of the refracted direction, 0 under total internal reflection
    double etaTI = 1.0;       ///< n_incident / n_transmitted along the direction of travel
};

/// Dielectric Fresnel for a ray arriving at cosine cosI (> 0: from the side the normal points to) at an
/// interface of relative index eta = n_inside / n_outside (Mitsuba's convention: a negative cosI means
/// the ray travels from the inside, and the relative index becomes 1/eta).
DielectricFresnel fresnelDielectric(double cosI, double eta);

/// Unpolarized reflectance of a conductor with complex index eta + i k, seen from a medium of index 1
/// (pbrt-v4 FrComplex: exact, through complex arithmetic); cosI is clamped to [0, 1].
double fresnelConductor(double cosI, double eta, double k);

/// Hemispherical average 2 * integral_0^1 F(mu; eta) mu dmu of the dielectric Fresnel reflectance by
/// adaptive quadrature (accurate to ~1e-12): the "diffuse Fresnel reflectance" of a smooth interface.
double diffuseFresnelReflectance(double eta);

} // namespace vkrt

#include "material/Ggx.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>

namespace vkrt {

double Ggx::d(const glm::dvec3& m) const
{
    if (m.z <= 0.0) return 0.0;
    double x = m.x / ax, y = m.y / ay;
    double s = x * x + y * y + m.z * m.z;
    return 1.0 / (std::numbers::pi * ax * ay * s * s);
}

double Ggx::lambda(const glm::dvec3& w) const
{
    double xy = ax * ax * w.x * w.x + ay * ay * w.y * w.y;
    if (xy == 0.0) return 0.0;
    double z2 = w.z * w.z;
    if (z2 == 0.0) return INFINITY;
    // -1 + sqrt(1 + t) loses digits for small t: t / (1 + sqrt(1 + t)) is the same number.
    double t = xy / z2;
    return 0.5 * t / (1.0 + std::sqrt(1.0 + t));
}

double Ggx::g1(const glm::dvec3& w, const glm::dvec3& m) const
{
    if (glm::dot(w, m) * w.z <= 0.0) return 0.0;
    return 1.0 / (1.0 + lambda(w));
}

double Ggx::g(const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& m) const
{
    return g1(wo, m) * g1(wi, m);
}

double Ggx::gCorrelated(const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& m) const
{
    if (glm::dot(wo, m) * wo.z <= 0.0 || glm::dot(wi, m) * wi.z <= 0.0) return 0.0;
    return 1.0 / (1.0 + lambda(wo) + lambda(wi));
}

double Ggx::visibleNormalPdf(const glm::dvec3& w, const glm::dvec3& m) const
{
    if (w.z <= 0.0) return 0.0;
    return g1(w, m) * std::max(0.0, glm::dot(w, m)) * d(m) / w.z;
}

glm::dvec3 Ggx::visibleNormalFromDisk(const glm::dvec3& w, double t1, double t2) const
{
    // Stretch the view direction to the configuration of unit roughness.
    glm::dvec3 vh = glm::normalize(glm::dvec3(ax * w.x, ay * w.y, w.z));
    double lenSq = vh.x * vh.x + vh.y * vh.y;
    glm::dvec3 b1 = lenSq > 0.0 ? glm::dvec3(-vh.y, vh.x, 0.0) / std::sqrt(lenSq) : glm::dvec3(1.0, 0.0, 0.0);
    glm::dvec3 b2 = glm::cross(vh, b1);
    // Warp the disk onto the projection of the visible hemisphere (half disk plus half ellipse).
    double s = 0.5 * (1.0 + vh.z);
    t2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - t1 * t1)) + s * t2;
    glm::dvec3 nh = t1 * b1 + t2 * b2 + std::sqrt(std::max(0.0, 1.0 - t1 * t1 - t2 * t2)) * vh;
    // Unstretch back to the distribution's roughness.
    return glm::normalize(glm::dvec3(ax * nh.x, ay * nh.y, std::max(1e-300, nh.z)));
}

glm::dvec3 Ggx::sampleVisibleNormal(const glm::dvec3& w, double u1, double u2) const
{
    double r = std::sqrt(u1);
    double phi = 2.0 * std::numbers::pi * u2;
    return visibleNormalFromDisk(w, r * std::cos(phi), r * std::sin(phi));
}

glm::dvec3 reflect(const glm::dvec3& w, const glm::dvec3& m)
{
    return 2.0 * glm::dot(w, m) * m - w;
}

} // namespace vkrt

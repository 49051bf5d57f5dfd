#include "deform.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace bvhlab {

namespace {

constexpr std::array<std::pair<DeformationKind, std::string_view>, 4> kNames{{
    {DeformationKind::Twist, "twist"},
    {DeformationKind::Bend, "bend"},
    {DeformationKind::Pulsate, "pulsate"},
    {DeformationKind::Wave, "wave"},
}};

std::string known_names() {
  std::string out;
  for (const auto& [kind, name] : kNames) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

double parse_number(std::string_view spec, std::string_view key, std::string_view text) {
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    throw std::invalid_argument("deformation '" + std::string(spec) + "': " + std::string(key) + " '" +
                                std::string(text) + "' is not a finite number");
  return value;
}

// The deformations work in the rest mesh's bounds: its centre, its longest axis and, of the two others,
// the shortest (a flat sheet's normal).
struct RestFrame {
  Vec3 center;
  Vec3 lo;
  int longest = 0;
  int shortest = 2;
  double length = 0;
};

RestFrame frame_of(const Mesh& rest) {
  const Box b = rest.bounds();
  const Vec3 e = b.extent();
  RestFrame f;
  f.center = b.center();
  f.lo = b.min;
  for (int k = 1; k < 3; ++k)
    if (e[k] > e[f.longest]) f.longest = k;
  f.shortest = -1;
  for (int k = 0; k < 3; ++k)
    if (k != f.longest && (f.shortest < 0 || e[k] <= e[f.shortest])) f.shortest = k;
  f.length = e[f.longest];
  return f;
}

// The third axis, so (longest, other, shortest) names all three.
int other_axis(const RestFrame& f) {
  return 3 - f.longest - f.shortest;
}

Vec3 twist(const Vec3& p, const RestFrame& f, double strength) {
  const double h = f.length > 0 ? (p[f.longest] - f.center[f.longest]) / f.length : 0;
  const double angle = strength * h, c = std::cos(angle), s = std::sin(angle);
  const int u = other_axis(f), v = f.shortest;
  const double du = p[u] - f.center[u], dv = p[v] - f.center[v];
  Vec3 out = p;
  out[u] = f.center[u] + c * du - s * dv;
  out[v] = f.center[v] + s * du + c * dv;
  return out;
}

// The longest axis onto an arc of curvature k = strength / length, curling towards the shortest axis. The
// centre stays fixed. Written without the radius 1/k, so small curvatures lose no precision.
Vec3 bend(const Vec3& p, const RestFrame& f, double strength) {
  const double k = f.length > 0 ? strength / f.length : 0;
  const double u = p[f.longest] - f.center[f.longest], y = p[f.shortest] - f.center[f.shortest];
  const double phi = u * k;
  const double sin_over = phi == 0 ? 1.0 : std::sin(phi) / phi;                          // sin(phi)/phi
  const double versin_over = phi == 0 ? 0.0 : 2 * std::pow(std::sin(phi / 2), 2) / phi;  // (1-cos)/phi
  Vec3 out = p;
  out[f.longest] = f.center[f.longest] + u * sin_over - y * std::sin(phi);
  out[f.shortest] = f.center[f.shortest] + u * versin_over + y * std::cos(phi);
  return out;
}

}  // namespace

std::string_view to_string(DeformationKind kind) {
  for (const auto& [k, name] : kNames)
    if (k == kind) return name;
  return "?";
}

Deformation default_deformation(DeformationKind kind) {
  switch (kind) {
    case DeformationKind::Twist:
    case DeformationKind::Bend:
      return {kind, std::numbers::pi / 2, 1, 0};
    case DeformationKind::Pulsate:
      return {kind, 0.2, 1, 0};
    case DeformationKind::Wave:
      return {kind, 0.05, 1, 0.5};
  }
  throw std::invalid_argument("unknown deformation kind");
}

void validate(const Deformation& d) {
  const std::string name(to_string(d.kind));
  if (!std::isfinite(d.amplitude))
    throw std::invalid_argument("deformation " + name + ": amplitude must be finite");
  if (d.cycles < 1)
    throw std::invalid_argument("deformation " + name + ": cycles must be at least 1, not " +
                                std::to_string(d.cycles));
  if (d.kind == DeformationKind::Pulsate && std::abs(d.amplitude) >= 1)
    throw std::invalid_argument(
        "deformation pulsate: amplitude must lie in (-1, 1) (a scale of 1 +- amplitude "
        "must stay positive), not " +
        std::to_string(d.amplitude));
  if (d.kind == DeformationKind::Wave && !(d.wavelength > 0 && std::isfinite(d.wavelength)))
    throw std::invalid_argument("deformation wave: wavelength must be a finite number > 0, not " +
                                std::to_string(d.wavelength));
}

Deformation parse_deformation(std::string_view spec) {
  const std::size_t colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  Deformation d;
  bool found = false;
  for (const auto& [kind, known] : kNames)
    if (known == name) d = default_deformation(kind), found = true;
  if (!found)
    throw std::invalid_argument("deformation '" + std::string(spec) + "': unknown name '" +
                                std::string(name) + "' (known: " + known_names() + ")");
  std::string_view rest = colon == std::string_view::npos ? std::string_view{} : spec.substr(colon + 1);
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      throw std::invalid_argument("deformation '" + std::string(spec) + "': '" + std::string(item) +
                                  "' is not key=value");
    const std::string_view key = item.substr(0, eq), text = item.substr(eq + 1);
    const double value = parse_number(spec, key, text);
    if (key == "amplitude") {
      d.amplitude = value;
    } else if (key == "cycles") {
      if (value != std::floor(value) || value < 1 || value > 1e6)
        throw std::invalid_argument("deformation '" + std::string(spec) +
                                    "': cycles must be a whole number " + "from 1 to 1e6, not " +
                                    std::string(text));
      d.cycles = static_cast<int>(value);
    } else if (key == "wavelength" && d.kind == DeformationKind::Wave) {
      d.wavelength = value;
    } else {
      throw std::invalid_argument("deformation '" + std::string(spec) + "': unknown parameter '" +
                                  std::string(key) + "' for " + std::string(name) +
                                  " (known: amplitude, cycles" +
                                  (d.kind == DeformationKind::Wave ? ", wavelength)" : ")"));
    }
  }
  validate(d);
  return d;
}

Mesh deform(const Mesh& rest, const Deformation& d, double t) {
  validate(d);
  if (rest.vertices.empty() || rest.triangles.empty())
    throw std::invalid_argument("deform: the rest mesh '" + rest.name + "' is empty");
  if (!std::isfinite(t)) throw std::invalid_argument("deform: time t must be finite");
  for (std::size_t v = 0; v < rest.vertices.size(); ++v)
    if (!rest.vertices[v].allFinite())
      throw std::invalid_argument("deform: vertex " + std::to_string(v) + " of '" + rest.name +
                                  "' is not finite");
  const RestFrame f = frame_of(rest);
  const double phase = 2 * std::numbers::pi * d.cycles * (t - std::floor(t));
  const double strength = d.amplitude * std::sin(phase);
  Mesh out = rest;
  if (d.amplitude == 0 || (strength == 0 && d.kind != DeformationKind::Wave)) return out;
  for (Vec3& p : out.vertices) {
    switch (d.kind) {
      case DeformationKind::Twist:
        p = twist(p, f, strength);
        break;
      case DeformationKind::Bend:
        p = bend(p, f, strength);
        break;
      case DeformationKind::Pulsate:
        p = f.center + (1 + strength) * (p - f.center);
        break;
      case DeformationKind::Wave: {
        const double x = f.length > 0 ? (p[f.longest] - f.lo[f.longest]) / f.length : 0;
        p[f.shortest] += d.amplitude * f.length * std::sin(2 * std::numbers::pi * x / d.wavelength - phase);
        break;
      }
    }
  }
  return out;
}

double frame_time(std::size_t frame, std::size_t frames) {
  if (frames == 0) throw std::invalid_argument("frame_time: the number of frames must be at least 1");
  return double(frame % frames) / double(frames);
}

Mesh cloth_grid(std::size_t n) {
  if (n == 0 || n > 46000)
    throw std::invalid_argument("cloth_grid: n must be from 1 to 46000 cells a side, not " +
                                std::to_string(n));
  Mesh m;
  m.name = "cloth_" + std::to_string(n);
  const std::size_t side = n + 1;
  m.vertices.reserve(side * side);
  for (std::size_t j = 0; j < side; ++j)
    for (std::size_t i = 0; i < side; ++i)
      m.vertices.emplace_back(double(i) / double(n), double(j) / double(n), 0);
  m.triangles.reserve(2 * n * n);
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const auto v00 = static_cast<std::uint32_t>(j * side + i), v10 = v00 + 1;
      const auto v01 = static_cast<std::uint32_t>(v00 + side), v11 = v01 + 1;
      m.triangles.push_back({v00, v10, v11});
      m.triangles.push_back({v00, v11, v01});
    }
  return m;
}

void check_same_topology(const Mesh& reference, const Mesh& frame, std::string_view frame_label) {
  const std::string label(frame_label);
  if (frame.vertices.size() != reference.vertices.size())
    throw std::invalid_argument(
        label + ": " + std::to_string(frame.vertices.size()) + " vertices, the first " + "frame has " +
        std::to_string(reference.vertices.size()) + " (a deforming mesh keeps its topology)");
  if (frame.triangles.size() != reference.triangles.size())
    throw std::invalid_argument(label + ": " + std::to_string(frame.triangles.size()) + " triangles, the " +
                                "first frame has " + std::to_string(reference.triangles.size()));
  for (std::size_t t = 0; t < frame.triangles.size(); ++t)
    if (frame.triangles[t] != reference.triangles[t]) {
      auto text = [](const TriangleIndices& i) {
        return "(" + std::to_string(i[0]) + ", " + std::to_string(i[1]) + ", " + std::to_string(i[2]) + ")";
      };
      throw std::invalid_argument(label + ": triangle " + std::to_string(t) + " has vertices " +
                                  text(frame.triangles[t]) + ", in the first frame " +
                                  text(reference.triangles[t]));
    }
  for (std::size_t v = 0; v < frame.vertices.size(); ++v)
    if (!frame.vertices[v].allFinite())
      throw std::invalid_argument(label + ": vertex " + std::to_string(v) + " is not finite");
}

}  // namespace bvhlab

#include "bvh/point_cloud.hpp"

#include "bvh/mesh_io.hpp"

#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

namespace bvhlab {

namespace {

[[noreturn]] void fail(std::string_view name, const std::string& what) {
  throw PointCloudError("point cloud '" + std::string(name) + "': " + what);
}

void check_finite(std::string_view name, std::span<const Vec3> v, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite()) fail(name, std::string(what) + " " + std::to_string(i) + " is not finite");
}

// ---- text helpers ----

/// Splits a line into numbers; nullopt when a token is not a number (locale-free, from_chars).
std::optional<std::vector<double>> parse_numbers(std::string_view line) {
  std::vector<double> out;
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size()) return out;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    const char* first = line.data() + i;
    const char* last = line.data() + j;
    if (*first == '+') ++first;  // from_chars refuses a leading '+'
    double value = 0;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec != std::errc() || ptr != last) return std::nullopt;
    out.push_back(value);
    i = j;
  }
}

/// Reads lines of `text` one at a time, counting them (1-based) for messages.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
    line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  [[nodiscard]] std::size_t number() const { return number_; }
  [[nodiscard]] std::size_t offset() const { return std::min(pos_, text_.size()); }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

// ---- XYZ ----

PointCloud read_xyz(std::string_view text, std::string_view name) {
  PointCloud cloud;
  cloud.name = std::string(name);
  LineReader lines(text);
  std::string_view line;
  std::size_t columns = 0;
  while (lines.next(line)) {
    const std::size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string_view::npos || line[start] == '#') continue;
    const auto numbers = parse_numbers(line);
    const std::string where = "line " + std::to_string(lines.number()) + ": ";
    if (!numbers) fail(name, where + "not a list of numbers");
    if (numbers->size() != 3 && numbers->size() != 6)
      fail(name,
           where + std::to_string(numbers->size()) + " numbers, expected 3 (x y z) or 6 (x y z nx ny nz)");
    if (columns == 0) columns = numbers->size();
    if (numbers->size() != columns)
      fail(name, where + std::to_string(numbers->size()) + " numbers, earlier lines have " +
                     std::to_string(columns));
    const auto& v = *numbers;
    cloud.positions.emplace_back(v[0], v[1], v[2]);
    if (columns == 6) cloud.normals.emplace_back(v[3], v[4], v[5]);
  }
  return cloud;
}

// ---- PLY ----

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyProperty {
  std::string name;
  int bytes = 0;  ///< size in a binary body
  bool is_float = false, is_signed = false;
};

std::optional<PlyProperty> ply_type(std::string_view type) {
  struct Entry {
    std::string_view a, b;
    int bytes;
    bool is_float, is_signed;
  };
  static constexpr Entry kTypes[] = {
      {"char", "int8", 1, false, true},    {"uchar", "uint8", 1, false, false},
      {"short", "int16", 2, false, true},  {"ushort", "uint16", 2, false, false},
      {"int", "int32", 4, false, true},    {"uint", "uint32", 4, false, false},
      {"float", "float32", 4, true, true}, {"double", "float64", 8, true, true},
  };
  for (const Entry& e : kTypes)
    if (type == e.a || type == e.b) return PlyProperty{"", e.bytes, e.is_float, e.is_signed};
  return std::nullopt;
}

std::vector<std::string> words(std::string_view line) {
  std::istringstream in{std::string(line)};
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::size_t vertices = 0;
  std::size_t faces = 0;                ///< the face element's count (0: none declared)
  std::vector<PlyProperty> properties;  ///< of the vertex element
  std::size_t body = 0;                 ///< offset of the first body byte
};

PlyHeader read_ply_header(std::string_view text, std::string_view name) {
  LineReader lines(text);
  std::string_view line;
  if (!lines.next(line) || words(line) != std::vector<std::string>{"ply"})
    fail(name, "not a PLY file (the first line is not 'ply')");
  PlyHeader h;
  bool have_format = false, in_vertex = false, seen_element = false;
  while (true) {
    if (!lines.next(line)) fail(name, "the header has no end_header");
    const std::vector<std::string> w = words(line);
    const std::string where = "header line " + std::to_string(lines.number()) + ": ";
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3) fail(name, where + "bad format line");
      if (w[1] == "ascii")
        h.format = PlyFormat::Ascii;
      else if (w[1] == "binary_little_endian")
        h.format = PlyFormat::BinaryLittle;
      else if (w[1] == "binary_big_endian")
        h.format = PlyFormat::BinaryBig;
      else
        fail(name, where + "unknown format '" + w[1] + "'");
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) fail(name, where + "bad element line");
      auto element_count = [&] {  // the element's count, a whole number
        std::size_t count = 0;
        const auto [ptr, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), count);
        if (ec != std::errc() || ptr != w[2].data() + w[2].size())
          fail(name, where + "bad " + w[1] + " count '" + w[2] + "'");
        return count;
      };
      if (!seen_element) {
        if (w[1] != "vertex") fail(name, where + "the first element is '" + w[1] + "', expected 'vertex'");
        h.vertices = element_count();
      }
      if (w[1] == "face") h.faces = element_count();
      in_vertex = !seen_element;
      seen_element = true;
    } else if (w[0] == "property") {
      if (!seen_element) fail(name, where + "a property before any element");
      if (!in_vertex) continue;  // later elements are not read
      if (w.size() >= 2 && w[1] == "list") fail(name, where + "a list property in the vertex element");
      if (w.size() != 3) fail(name, where + "bad property line");
      std::optional<PlyProperty> p = ply_type(w[1]);
      if (!p) fail(name, where + "unknown property type '" + w[1] + "'");
      p->name = w[2];
      h.properties.push_back(*p);
    } else {
      fail(name, where + "unknown keyword '" + w[0] + "'");
    }
  }
  if (!have_format) fail(name, "the header has no format line");
  if (!seen_element) fail(name, "the header declares no vertex element");
  h.body = lines.offset();
  return h;
}

double read_binary(const unsigned char* p, const PlyProperty& prop, bool big_endian) {
  unsigned char b[8];
  std::memcpy(b, p, prop.bytes);
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + prop.bytes);
  if (prop.is_float) {
    if (prop.bytes == 4) {
      float f;
      std::memcpy(&f, b, 4);
      return f;
    }
    double d;
    std::memcpy(&d, b, 8);
    return d;
  }
  std::uint64_t u = 0;
  std::memcpy(&u, b, prop.bytes);  // little-endian hosts; big-endian ones fix below
  if constexpr (std::endian::native == std::endian::big) u >>= 8 * (8 - prop.bytes);
  if (prop.is_signed) {
    const int shift = 64 - 8 * prop.bytes;
    return double(std::int64_t(u << shift) >> shift);
  }
  return double(u);
}

PointCloud read_ply(std::string_view text, std::string_view name) {
  const PlyHeader h = read_ply_header(text, name);
  std::array<int, 6> column{-1, -1, -1, -1, -1, -1};
  static constexpr const char* kNames[6] = {"x", "y", "z", "nx", "ny", "nz"};
  for (std::size_t i = 0; i < h.properties.size(); ++i)
    for (int c = 0; c < 6; ++c)
      if (h.properties[i].name == kNames[c]) column[c] = int(i);
  for (int c = 0; c < 3; ++c)
    if (column[c] < 0) fail(name, std::string("the vertex element has no property '") + kNames[c] + "'");
  const int normal_columns = (column[3] >= 0) + (column[4] >= 0) + (column[5] >= 0);
  if (normal_columns != 0 && normal_columns != 3)
    fail(name, "the vertex element has some of nx, ny, nz but not all three");
  const bool normals = normal_columns == 3;

  PointCloud cloud;
  cloud.name = std::string(name);
  const std::size_t n = h.vertices;
  std::vector<double> record(h.properties.size());
  auto store = [&] {
    cloud.positions.emplace_back(record[column[0]], record[column[1]], record[column[2]]);
    if (normals) cloud.normals.emplace_back(record[column[3]], record[column[4]], record[column[5]]);
  };
  if (h.format == PlyFormat::Ascii) {
    LineReader lines(text.substr(h.body));
    std::string_view line;
    for (std::size_t v = 0; v < n; ++v) {
      if (!lines.next(line))
        fail(name, "the body ends after " + std::to_string(v) + " of " + std::to_string(n) + " vertices");
      const auto numbers = parse_numbers(line);
      if (!numbers || numbers->size() != record.size())
        fail(name, "vertex " + std::to_string(v) + ": expected " + std::to_string(record.size()) +
                       " numbers on its body line");
      record = *numbers;
      store();
    }
    return cloud;
  }
  std::size_t stride = 0;
  for (const PlyProperty& p : h.properties) stride += std::size_t(p.bytes);
  const std::size_t available = text.size() - h.body;
  if (stride == 0 || n > available / stride)
    fail(name, "the body holds " + std::to_string(stride ? available / stride : 0) +
                   " vertices, the header "
                   "declares " +
                   std::to_string(n));
  cloud.positions.reserve(n);
  const auto* p = reinterpret_cast<const unsigned char*>(text.data() + h.body);
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t i = 0; i < h.properties.size(); ++i) {
      record[i] = read_binary(p, h.properties[i], h.format == PlyFormat::BinaryBig);
      p += h.properties[i].bytes;
    }
    store();
  }
  return cloud;
}

// ---- sampling ----

/// SplitMix64: a small generator whose output is fixed by its integer arithmetic on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1), 53 bits.
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

Vec3 cross(const Vec3& a, const Vec3& b) {  // spelled out: no library-chosen evaluation order
  return Vec3(a.y() * b.z() - a.z() * b.y(), a.z() * b.x() - a.x() * b.z(), a.x() * b.y() - a.y() * b.x());
}
double length(const Vec3& v) {
  return std::sqrt(v.x() * v.x() + v.y() * v.y() + v.z() * v.z());
}

double triangle_area(const TrianglePoints& p) {
  return 0.5 * length(cross(p[1] - p[0], p[2] - p[0]));
}

/// Area-weighted triangle choice and uniform points in triangles.
class MeshSampler {
 public:
  explicit MeshSampler(const Mesh& mesh) : mesh_(mesh) {
    cumulative_.reserve(mesh.triangle_count());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      total_ += triangle_area(mesh.triangle(t));
      cumulative_.push_back(total_);
    }
    if (!(total_ > 0) || !std::isfinite(total_))
      throw std::invalid_argument("sample: mesh '" + mesh.name + "' has no finite positive area");
  }
  [[nodiscard]] double area() const { return total_; }
  /// A point and its triangle's unit normal.
  std::pair<Vec3, Vec3> sample(Random& random) const {
    const double u = random.uniform() * total_;
    auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), u);
    if (it == cumulative_.end()) --it;  // u rounded up to the total: the last triangle with area
    while (it != cumulative_.begin() && *it == *(it - 1)) --it;
    const TrianglePoints p = mesh_.triangle(std::size_t(it - cumulative_.begin()));
    const double s = std::sqrt(random.uniform()), r = random.uniform();
    const Vec3 point = (1 - s) * p[0] + (s * (1 - r)) * p[1] + (s * r) * p[2];
    const Vec3 n = cross(p[1] - p[0], p[2] - p[0]);
    return {point, n / length(n)};
  }

 private:
  const Mesh& mesh_;
  std::vector<double> cumulative_;
  double total_ = 0;
};

}  // namespace

void validate(const PointCloud& cloud, std::size_t min_points) {
  const std::string name = cloud.name.empty() ? "<unnamed>" : cloud.name;
  if (cloud.positions.empty()) fail(name, "has no points");
  if (cloud.size() < min_points)
    fail(name, "has " + std::to_string(cloud.size()) + " points, the kernel needs at least " +
                   std::to_string(min_points));
  check_finite(name, cloud.positions, "point");
  for (std::size_t i = 0; i < cloud.size(); ++i)  // the meshes' limit: beyond it a double spaces by 0.1
    if (cloud.positions[i].cwiseAbs().maxCoeff() > MeshPrecisionLimits::max_abs_coordinate)
      fail(name, "point " + std::to_string(i) +
                     " has a coordinate beyond 1e15 (the queries' precision ends there)");
  if (cloud.has_normals()) {
    if (cloud.normals.size() != cloud.size())
      fail(name,
           std::to_string(cloud.normals.size()) + " normals for " + std::to_string(cloud.size()) + " points");
    check_finite(name, cloud.normals, "normal");
  }
  if (cloud.has_areas()) {
    if (cloud.areas.size() != cloud.size())
      fail(name,
           std::to_string(cloud.areas.size()) + " areas for " + std::to_string(cloud.size()) + " points");
    for (std::size_t i = 0; i < cloud.areas.size(); ++i)
      if (!std::isfinite(cloud.areas[i]) || cloud.areas[i] < 0)
        fail(name, "area " + std::to_string(i) + " is negative or not finite");
  }
  if (cloud.size() > 1 && std::all_of(cloud.positions.begin(), cloud.positions.end(),
                                      [&](const Vec3& p) { return p == cloud.positions[0]; }))
    fail(name, "all " + std::to_string(cloud.size()) + " points are coincident");
}

PointCloud load_point_cloud_from_memory(std::span<const std::byte> bytes, std::string_view format,
                                        std::string_view name) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  PointCloud cloud;
  if (format == "ply")
    cloud = read_ply(text, name);
  else if (format == "xyz")
    cloud = read_xyz(text, name);
  else
    fail(name, "unknown point cloud format '" + std::string(format) + "' (expected ply or xyz)");
  validate(cloud);
  return cloud;
}

namespace {

/// The file's extension in lower case (".ply").
std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

bool is_point_cloud_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".xyz") return true;
  if (ext != ".ply") return false;
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');  // a header longer than this is no cloud this function vouches for
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  try {
    return read_ply_header(head, path.string()).faces == 0;
  } catch (const PointCloudError&) {
    return false;  // the mesh loader names the problem
  }
}

PointCloud load_point_cloud(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext != ".ply" && ext != ".xyz")
    fail(path.string(), "unknown extension '" + ext + "' (expected .ply or .xyz)");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path.string(), "cannot be opened");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string data = std::move(buffer).str();
  PointCloud cloud = load_point_cloud_from_memory(std::as_bytes(std::span(data.data(), data.size())),
                                                  ext.substr(1), path.string());
  cloud.name = path.stem().string();
  return cloud;
}

void save_point_cloud_ply(const PointCloud& cloud, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) fail(path.string(), "cannot be written");
  out << "ply\nformat ascii 1.0\nelement vertex " << cloud.size()
      << "\nproperty double x\nproperty double y\n"
      << "property double z\n";
  if (cloud.has_normals()) out << "property double nx\nproperty double ny\nproperty double nz\n";
  out << "end_header\n";
  out.precision(17);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.positions[i];
    out << p.x() << ' ' << p.y() << ' ' << p.z();
    if (cloud.has_normals())
      out << ' ' << cloud.normals[i].x() << ' ' << cloud.normals[i].y() << ' ' << cloud.normals[i].z();
    out << '\n';
  }
  if (!out) fail(path.string(), "write failed");
}

double surface_area(const Mesh& mesh) {
  double total = 0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) total += triangle_area(mesh.triangle(t));
  return total;
}

PointCloud sample_uniform(const Mesh& mesh, std::size_t n, std::uint64_t seed) {
  if (n == 0) throw std::invalid_argument("sample_uniform: n must be at least 1");
  const MeshSampler sampler(mesh);
  Random random(seed);
  PointCloud cloud;
  cloud.name = mesh.name;
  cloud.positions.reserve(n);
  cloud.normals.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto [p, normal] = sampler.sample(random);
    cloud.positions.push_back(p);
    cloud.normals.push_back(normal);
  }
  cloud.areas.assign(n, sampler.area() / double(n));
  return cloud;
}

PointCloud sample_varying(const Mesh& mesh, std::size_t n, std::uint64_t seed, double ratio) {
  if (n == 0) throw std::invalid_argument("sample_varying: n must be at least 1");
  if (!(ratio >= 1 && ratio <= 1000))
    throw std::invalid_argument("sample_varying: ratio must be in [1, 1000], got " + std::to_string(ratio));
  const MeshSampler sampler(mesh);
  const Box box = mesh.bounds();
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (box.extent()[a] > box.extent()[axis]) axis = a;
  const double lo = box.min[axis], extent = box.extent()[axis];
  Random random(seed);
  PointCloud cloud;
  cloud.name = mesh.name;
  cloud.positions.reserve(n);
  cloud.normals.reserve(n);
  while (cloud.size() < n) {
    const auto [p, normal] = sampler.sample(random);
    const double t = extent > 0 ? (p[axis] - lo) / extent : 1.0;
    // Accept with probability proportional to 1 + (ratio - 1) t: density 1 at lo, ratio at lo + extent.
    if (random.uniform() * ratio < 1 + (ratio - 1) * t) {
      cloud.positions.push_back(p);
      cloud.normals.push_back(normal);
    }
  }
  return cloud;
}

std::vector<double> kth_neighbour_distances(std::span<const Vec3> points, std::size_t k) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Traits = CGAL::Search_traits_3<Kernel>;
  using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
  if (k == 0) throw std::invalid_argument("kth_neighbour_distances: k must be at least 1");
  check_finite("<points>", points, "point");
  if (points.size() < k + 1)
    fail("<points>", std::to_string(points.size()) + " points, the k-th neighbour (k = " + std::to_string(k) +
                         ") needs at least " + std::to_string(k + 1));
  std::vector<Kernel::Point_3> cgal_points;
  cgal_points.reserve(points.size());
  for (const Vec3& p : points) cgal_points.emplace_back(p.x(), p.y(), p.z());
  Search::Tree tree(cgal_points.begin(), cgal_points.end());
  tree.build();
  std::vector<double> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    // k + 1 neighbours: the point itself (or a copy of it) comes first at distance 0.
    Search search(tree, cgal_points[i], unsigned(k + 1));
    double farthest = 0;
    for (const auto& [point, squared] : search) farthest = std::max(farthest, squared);
    out[i] = std::sqrt(farthest);
  }
  return out;
}

void assign_knn_areas(PointCloud& cloud, std::size_t k) {
  const std::vector<double> r = kth_neighbour_distances(cloud.positions, k);
  cloud.areas.resize(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) cloud.areas[i] = std::numbers::pi * r[i] * r[i] / double(k);
}

}  // namespace bvhlab

// Point cloud files (bvh/point_cloud.hpp): PLY and XYZ read from files and memory, a cloud file told from a
// mesh file, an ascii PLY written.
#include "bvh/point_cloud.hpp"

#include "bvh/io/ply_internal.hpp"
#include "bvh/io/text_internal.hpp"

#include <array>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {
namespace {

// Worded as validate (bvh/point_cloud.cpp) words its PointCloudError.
[[noreturn]] void fail(std::string_view name, const std::string& what) {
  throw PointCloudError("point cloud '" + std::string(name) + "': " + what);
}

// ---- XYZ ----

/// Splits a line into numbers at spaces, tabs and CR; nullopt when a token is not a number.
std::optional<std::vector<double>> parse_numbers(std::string_view line) {
  auto separates = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::vector<double> out;
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && separates(line[i])) ++i;
    if (i == line.size()) return out;
    std::size_t j = i;
    while (j < line.size() && !separates(line[j])) ++j;
    const std::optional<double> value = io::parse_number(line.substr(i, j - i));
    if (!value) return std::nullopt;
    out.push_back(*value);
    i = j;
  }
}

PointCloud read_xyz(std::string_view text, std::string_view name) {
  PointCloud cloud;
  cloud.name = std::string(name);
  io::LineReader lines(text);
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

/// Which vertex properties hold x, y, z and nx, ny, nz (the last of a name counts).
struct CloudColumns {
  std::array<std::size_t, 6> index{};
  bool normals = false;
};

CloudColumns cloud_columns(const io::PlyElement& vertex, std::string_view name) {
  static constexpr const char* kNames[6] = {"x", "y", "z", "nx", "ny", "nz"};
  std::array<int, 6> column{-1, -1, -1, -1, -1, -1};
  for (std::size_t i = 0; i < vertex.properties.size(); ++i)
    for (int c = 0; c < 6; ++c)
      if (vertex.properties[i].name == kNames[c]) column[c] = int(i);
  for (int c = 0; c < 3; ++c)
    if (column[c] < 0) fail(name, std::string("the vertex element has no property '") + kNames[c] + "'");
  const int normal_columns = (column[3] >= 0) + (column[4] >= 0) + (column[5] >= 0);
  if (normal_columns != 0 && normal_columns != 3)
    fail(name, "the vertex element has some of nx, ny, nz but not all three");
  CloudColumns out;
  out.normals = normal_columns == 3;
  for (int c = 0; c < (out.normals ? 6 : 3); ++c) out.index[c] = std::size_t(column[c]);
  return out;
}

// A binary body is measured before it is read, so that a huge vertex count reserves nothing.
void check_binary_size(std::string_view text, const io::PlyHeader& h, std::string_view name) {
  const io::PlyElement& vertices = h.elements.front();
  std::size_t stride = 0;
  for (const io::PlyProperty& p : vertices.properties) stride += p.value.bytes;
  const std::size_t available = text.size() - *h.body;
  if (stride == 0 || vertices.count > available / stride)
    fail(name, "the body holds " + std::to_string(stride ? available / stride : 0) +
                   " vertices, the header declares " + std::to_string(vertices.count));
}

PointCloud read_ply(std::string_view text, std::string_view name) {
  const io::PlyHeaderRead read = io::read_ply_header(text, io::PlyGrammar::PointCloud);
  if (!read.problem.empty()) fail(name, read.problem);
  const io::PlyHeader& h = read.header;
  const io::PlyElement& vertices = h.elements.front();
  const CloudColumns columns = cloud_columns(vertices, name);
  PointCloud cloud;
  cloud.name = std::string(name);
  if (h.format != io::PlyFormat::Ascii) {
    check_binary_size(text, h, name);
    cloud.positions.reserve(vertices.count);
  }
  const auto& k = columns.index;
  const auto store = [&](std::size_t, std::span<const double> v) {
    cloud.positions.emplace_back(v[k[0]], v[k[1]], v[k[2]]);
    if (columns.normals) cloud.normals.emplace_back(v[k[3]], v[k[4]], v[k[5]]);
  };
  // The vertices only; later elements (faces, edges) are not read.
  const auto stop = io::walk_ply_body(text, h, {io::kCloudText, 1, true}, store);
  if (stop && stop->kind == io::PlyStop::DataEnds)
    fail(name, "the body ends after " + std::to_string(stop->index) + " of " +
                   std::to_string(vertices.count) + " vertices");
  if (stop)
    fail(name, "vertex " + std::to_string(stop->index) + ": expected " +
                   std::to_string(vertices.properties.size()) + " numbers on its body line");
  return cloud;
}

/// The file's extension in lower case (".ply").
std::string lower_extension(const std::filesystem::path& path) {
  return io::lower_case(path.extension().string());
}

}  // namespace

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

bool is_point_cloud_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".xyz") return true;
  if (ext != ".ply") return false;
  std::ifstream in(path, std::ios::binary);
  std::string head(io::kPlyHeaderBytes,
                   '\0');  // a header longer than this is no cloud this function vouches for
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(std::size_t(in.gcount()));
  const io::PlyHeaderRead read = io::read_ply_header(head, io::PlyGrammar::PointCloud);
  if (!read.problem.empty()) return false;  // the mesh loader names the problem
  const io::PlyElement* faces = read.header.find("face");
  return faces == nullptr || faces->count == 0;
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

}  // namespace bvhlab

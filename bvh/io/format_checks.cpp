// The mesh loader's checks of its input before assimp reads it (bvh/io/mesh_load_internal.hpp): which format
// it is read as, and per format what made assimp crash, hang or allocate without bound (found by tests/fuzz).
#include "bvh/io/mesh_load_internal.hpp"
#include "bvh/io/ply_internal.hpp"
#include "bvh/io/text_internal.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab::io {

bool has_ply_magic(std::string_view text) {
  return lower_case(text.substr(0, 3)) == "ply";
}

bool ply_header_unterminated(std::string_view text) {
  if (!has_ply_magic(text)) return false;
  for (std::size_t position = 0; position < text.size();) {
    const std::size_t end = std::min(text.find('\n', position), text.size());
    const std::string_view line = text.substr(position, end - position);
    position = end + 1;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line.compare(first, 10, "end_header") != 0) continue;
    // assimp's token match takes only these after the keyword (a vertical tab, say, still hangs it).
    if (first + 10 == line.size() ||
        std::string_view(" \t\r\f\0", 5).find(line[first + 10]) != std::string_view::npos)
      return false;
  }
  return true;
}

namespace {

// ---------------------------------------------------------------------------------------------------------
// Element counts: OFF and PLY headers declare them, and assimp allocates for them before reading a single
// element: a 60-byte OFF file declaring 14294967295 faces asked for 22 GB (found by tests/fuzz). Every
// element takes at least one byte of the file, so a count above the file's size is refused up front.

/// The problem with a header declaring `count` elements (`what`) in a file of `size` bytes; "" when none.
std::string count_exceeds_size(std::uint64_t count, const std::string& what, std::uint64_t size) {
  return count > size ? "header declares " + std::to_string(count) + " " + what + " but the file has only " +
                            std::to_string(size) + " bytes (corrupt or truncated?)"
                      : std::string();
}

// Whether a lower-case first token starts with the OFF keyword and its optional prefixes (ST, C, N, 4, n).
bool starts_with_off_keyword(std::string_view token) {
  const std::size_t at = token.find("off");
  return at != std::string_view::npos && at <= 3 &&
         token.find_first_not_of("abcdefghijklmnopqrstuvwxyz") >= at;
}

// The vertex and face counts assimp 5.2's OFF reader takes from `text`, found by walking the header as it
// does: optional ST, C, N, 4, n prefixes and the keyword, then numbers, where a '#' after a number starts a
// comment to the end of the line ("8### 12 0" is 8 and then the next line's number), and a count wraps
// around at 2^32 as its strtoul10 does. Tokenising the header differently let a 275-byte file ask for 64 GB
// (found by tests/fuzz).
std::array<std::uint32_t, 2> off_header_counts(std::string_view text) {
  text = text.substr(0, text.find('\0'));                          // assimp's copy ends at the first NUL
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // and has no UTF-8 byte-order mark
  std::size_t car = 0;
  auto skip_blanks = [&] {
    while (car < text.size() && std::string_view(" \t\r\n").find(text[car]) != std::string_view::npos) ++car;
  };
  auto next_token = [&] {
    skip_blanks();
    while (car < text.size() && (text[car] == '#' || text[car] == '\n' || text[car] == '\r')) {
      while (car < text.size() && text[car] != '\r' && text[car] != '\n') ++car;
      skip_blanks();
    }
  };
  auto take = [&](std::string_view prefix) {
    const bool match = text.substr(car, prefix.size()) == prefix;
    if (match) car += prefix.size();
    return match;
  };
  auto number = [&] {
    std::uint32_t value = 0;
    for (; car < text.size() && text[car] >= '0' && text[car] <= '9'; ++car)
      value = value * 10 + static_cast<std::uint32_t>(text[car] - '0');
    return value;
  };
  next_token();
  take("ST");
  take("C");
  take("N");
  take("4");
  const bool dimension = take("n");
  take("OFF");
  next_token();
  if (dimension) {
    number();
    next_token();
  }
  next_token();
  const std::uint32_t vertices = number();
  next_token();
  return {vertices, number()};
}

std::string off_count_problem(std::string_view text) {
  const auto [vertices, faces] = off_header_counts(text);
  if (auto problem = count_exceeds_size(vertices, "vertices", text.size()); !problem.empty()) return problem;
  return count_exceeds_size(faces, "faces", text.size());
}

// ---------------------------------------------------------------------------------------------------------
// PLY, read with the loaders' one PLY reader (bvh/io/ply_internal.hpp) by the grammar assimp's reader has.

// The element counts of a PLY header (in its first kPlyHeaderBytes), and whether it declares an element or
// the format twice: that makes assimp size its arrays from one declaration and fill them from the other, a
// heap overflow inside assimp (found by tests/fuzz under valgrind). Runs on any input whose first word is the
// magic, whatever format it is read as.
std::string ply_declaration_problem(std::string_view text) {
  PlyHeaderLines lines(text.substr(0, kPlyHeaderBytes));
  std::vector<std::string> seen;
  bool after_magic = false;
  while (lines.next()) {
    std::span<const std::string> w = lines.words();
    if (!after_magic) {  // the magic is the first word; the rest of its line is read like any line
      if (w.empty()) continue;
      if (lower_case(w[0]) != "ply") return {};
      after_magic = true;
      w = w.subspan(1);
    }
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    const bool format = w[0] == "format";
    if (!format && (w[0] != "element" || w.size() < 3)) continue;
    const std::string name = format ? "format" : w[1];
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      return "PLY header declares " + (format ? std::string("the format") : "element '" + name + "'") +
             " twice";
    seen.push_back(name);
    if (format) continue;
    if (auto problem = count_exceeds_size(leading_count(w[2]), "'" + name + "' elements", text.size());
        !problem.empty())
      return problem;
  }
  return {};
}

std::string describe_body_stop(const PlyBodyStop& stop, const PlyHeader& header) {
  const PlyElement& element = header.elements[stop.element];
  const std::string which = "'" + element.name + "' " + std::to_string(stop.index);
  if (stop.kind == PlyStop::DataEnds)
    return "PLY data ends inside element " + which + " of " + std::to_string(element.count) +
           " (corrupt or truncated?)";
  if (stop.kind == PlyStop::BlankLine) return "PLY element " + which + " is a blank line (corrupt?)";
  if (stop.kind == PlyStop::TooFewValues)
    return "PLY element " + which + " has fewer values on its line than the header declares (corrupt?)";
  // The only other way a walk that reads no values stops.
  return "PLY element " + which + " holds a list of " + std::to_string(stop.list_count) +
         " values, more than its data has (corrupt?)";
}

// assimp 5.2's PLY reader trusts every list's own count: one face whose ASCII count read 6.6e25 made it
// allocate until it ran out of memory (found by tests/fuzz). So a PLY body is walked once, element by element
// as the header declares them, before assimp reads it: every value must be there and every list must fit in
// what is left of the file. A header this walk does not understand is refused too (an unknown property type
// let the same huge count through). In ASCII, assimp reads one element per line, ignoring what follows its
// properties, and reads a blank line as an element; the walk reads lines as it does (kAssimpText) and refuses
// blank ones rather than guess. Returns the problem, or "" for a PLY file whose body matches its header (and
// for input that is not PLY).
std::string ply_body_problem(std::string_view text) {
  if (!has_ply_magic(text)) return {};
  const PlyHeaderRead read = read_ply_header(text, PlyGrammar::Assimp);
  if (!read.problem.empty() || !read.header.body) return read.problem;  // no end_header: refused before
  const std::optional<PlyBodyStop> stop = walk_ply_body(text, read.header, PlyBodyRules{});
  return stop ? describe_body_stop(*stop, read.header) : std::string();
}

// ---------------------------------------------------------------------------------------------------------
// OBJ, MS3D, STL, and text in general.

// OBJ is a text format. assimp 5.2's OBJ reader, given from memory an `mtllib` line whose name holds NUL
// bytes, writes through a wild pointer (a SEGV, found by tests/fuzz; valgrind shows an invalid write). A NUL
// byte has no business in an OBJ file, so one is refused up front.
std::string binary_data_in_obj(std::string_view text, std::string_view format) {
  if (format != "obj") return {};
  const std::size_t nul = text.find('\0');
  return nul == std::string_view::npos
             ? std::string()
             : "OBJ is a text format, but byte " + std::to_string(nul) + " is NUL (binary data?)";
}

// assimp 5.2's MS3D reader checks a group's triangle indices and a triangle's vertex indices with > where it
// needs >=: index n of n is read past the end of its list, or through null when the list is empty (a group
// naming triangle 0 of none; found by tests/fuzz). It also builds the joint tree recursively. So the indices,
// the groups' materials and the joint count are checked first, walking the file as assimp reads it. Where
// the file ends early assimp stops with an error of its own, and so does this walk, silently.
constexpr std::size_t kMaxMs3dJoints = 1024;  // MilkShape itself allows 128

std::string ms3d_problem(std::string_view bytes) {
  std::size_t at = 14;  // magic and version, which assimp checks
  bool whole = true;
  auto skip = [&](std::uint64_t n) {
    whole = whole && n <= bytes.size() - std::min(at, bytes.size());
    at = whole ? at + n : bytes.size();
  };
  auto unsigned_le = [&](std::size_t n) {
    std::uint32_t value = 0;
    const std::size_t start = at;
    skip(n);
    for (std::size_t i = 0; whole && i < n; ++i)
      value |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[start + i])) << (8 * i);
    return value;
  };
  const std::uint32_t vertices = unsigned_le(2);
  skip(15ull * vertices);  // flags, position, bone, reference count
  const std::uint32_t triangles = unsigned_le(2);
  for (std::uint32_t t = 0; whole && t < triangles; ++t) {
    skip(2);
    for (int k = 0; k < 3; ++k)
      if (const std::uint32_t v = unsigned_le(2); whole && v >= vertices)
        return "MS3D triangle " + std::to_string(t) + " refers to vertex " + std::to_string(v) + " of " +
               std::to_string(vertices);
    skip(36 + 24 + 2);  // normals, uv, smoothing group, group
  }
  const std::uint32_t groups = unsigned_le(2);
  std::vector<std::uint32_t> group_materials;
  for (std::uint32_t g = 0; whole && g < groups; ++g) {
    skip(33);  // flags, name
    const std::uint32_t count = unsigned_le(2);
    for (std::uint32_t j = 0; whole && j < count; ++j)
      if (const std::uint32_t t = unsigned_le(2); whole && t >= triangles)
        return "MS3D group " + std::to_string(g) + " refers to triangle " + std::to_string(t) + " of " +
               std::to_string(triangles);
    group_materials.push_back(unsigned_le(1));
  }
  const std::uint32_t materials = unsigned_le(2);
  for (std::size_t g = 0; whole && materials > 0 && g < group_materials.size(); ++g)
    if (group_materials[g] != 0xFF && group_materials[g] >= materials)
      return "MS3D group " + std::to_string(g) + " uses material " + std::to_string(group_materials[g]) +
             " of " + std::to_string(materials);
  skip(361ull * materials + 12);  // materials; fps, current time, frame count
  const std::uint32_t joints = unsigned_le(2);
  if (whole && joints > kMaxMs3dJoints)
    return "MS3D file has " + std::to_string(joints) + " joints; more than " +
           std::to_string(kMaxMs3dJoints) + " are not read";
  return {};
}

// Binary STL, as assimp recognises it: an 80-byte header, a triangle count, 50 bytes per triangle.
bool is_binary_stl(std::string_view bytes) {
  if (bytes.size() < 84) return false;
  std::uint64_t count = 0;
  for (int i = 3; i >= 0; --i) count = (count << 8) | static_cast<unsigned char>(bytes[80 + i]);
  return 84 + 50 * count == bytes.size();
}

// assimp converts text that starts with a UTF-16 or UTF-32 byte-order mark in ways it does not check (its
// UTF-32 path reads past its buffer), and the checks here read text formats as single bytes: such text is
// refused.
std::string wide_text_problem(std::string_view bytes, std::string_view format) {
  const bool text_format = format == "obj" || format == "off" || (format == "stl" && !is_binary_stl(bytes));
  const auto byte = [&](std::size_t i) {
    return i < bytes.size() ? static_cast<unsigned char>(bytes[i]) : 0u;
  };
  const bool wide = (byte(0) == 0xFE && byte(1) == 0xFF) || (byte(0) == 0xFF && byte(1) == 0xFE);
  return text_format && wide ? "text in UTF-16 or UTF-32 is not read (save it as ASCII or UTF-8)" : "";
}

/// OBJ: a line with one of its statements among the first lines.
bool looks_like_obj(std::string_view bytes) {
  const std::string_view head = bytes.substr(0, 4096);
  for (std::size_t position = 0; position < head.size();) {
    const std::size_t end = std::min(head.find('\n', position), head.size());
    std::string_view line = head.substr(position, end - position);
    position = end + 1;
    line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
    for (const char* statement : {"v ", "vt ", "vn ", "f ", "o ", "g ", "s ", "mtllib ", "usemtl "})
      if (line.rfind(statement, 0) == 0) return true;
  }
  return false;
}

}  // namespace

std::string read_format(std::string_view bytes, const std::string& hint) {
  if (std::find(std::begin(kReadFormats), std::end(kReadFormats), hint) != std::end(kReadFormats))
    return hint;
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  const std::string_view start = first == std::string_view::npos ? std::string_view() : bytes.substr(first);
  const std::string token =
      lower_case(start.substr(0, std::min<std::size_t>(start.find_first_of(" \t\r\n"), 64)));
  if (bytes.substr(0, 4) == "glTF") return "glb";
  if (start.substr(0, 1) == "{") return "gltf";
  if (has_ply_magic(bytes)) return "ply";
  if (bytes.substr(0, 10) == "MS3D000000") return "ms3d";
  if (starts_with_off_keyword(token)) return "off";
  if (token.rfind("solid", 0) == 0) return "stl";
  if (is_binary_stl(bytes)) return "stl";
  if (looks_like_obj(bytes)) return "obj";
  return {};
}

std::string input_problem(std::string_view bytes, const std::string& format) {
  // The PLY checks start at the magic; assimp's reader skips what precedes it (NUL bytes let a header without
  // end_header through to its endless loop; found by tests/fuzz). The PLY rules put the magic first.
  if (format == "ply" && !has_ply_magic(bytes)) return "not a PLY file: it must start with 'ply'";
  // The first problem in this order is the one reported.
  std::string problem = wide_text_problem(bytes, format);
  if (problem.empty()) problem = format == "off" ? off_count_problem(bytes) : ply_declaration_problem(bytes);
  if (problem.empty()) problem = ply_body_problem(bytes);
  if (problem.empty()) problem = binary_data_in_obj(bytes, format);
  if (problem.empty() && format == "ms3d") problem = ms3d_problem(bytes);
  return problem;
}

}  // namespace bvhlab::io

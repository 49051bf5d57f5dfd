#include "bvh/gltf_reduce.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>

namespace bvhlab::detail {
namespace {

using Json = nlohmann::json;

[[noreturn]] void refuse(const std::string& problem) {
  throw GltfRefused(problem);
}

std::uint32_t little_endian_u32(std::string_view bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i)
    value |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + i])) << (8 * i);
  return value;
}

void append_u32(std::string& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

struct GlbParts {
  std::string_view json;
  std::optional<std::string_view> bin;
};

// The GLB container as assimp reads it: 12-byte header, a JSON chunk, then a BIN chunk if one follows the
// JSON chunk's 4-byte padding.
GlbParts split_glb(std::string_view in) {
  if (in.size() < 20 || in.substr(0, 4) != "glTF") refuse("not a binary glTF (GLB) file: no glTF header");
  const std::uint32_t version = little_endian_u32(in, 4);
  if (version != 2) refuse("binary glTF version " + std::to_string(version) + " is not read (only 2)");
  const std::uint32_t length = little_endian_u32(in, 8);
  if (length != in.size())
    refuse("GLB header says " + std::to_string(length) + " bytes, the file has " + std::to_string(in.size()) +
           " (truncated or corrupt?)");
  const std::uint32_t json_length = little_endian_u32(in, 12);
  if (little_endian_u32(in, 16) != kChunkJson) refuse("the first GLB chunk is not JSON");
  if (json_length > in.size() - 20) refuse("the GLB JSON chunk runs past the end of the file");
  GlbParts parts{in.substr(20, json_length), std::nullopt};
  const std::size_t bin_at = 20 + ((std::size_t{json_length} + 3) & ~std::size_t{3});
  if (bin_at + 8 <= in.size()) {
    const std::uint32_t bin_length = little_endian_u32(in, bin_at);
    if (little_endian_u32(in, bin_at + 4) != kChunkBin) refuse("the second GLB chunk is not BIN");
    if (bin_length > in.size() - bin_at - 8) refuse("the GLB BIN chunk runs past the end of the file");
    parts.bin = in.substr(bin_at + 8, bin_length);
  }
  return parts;
}

/// Whether objects and arrays nest more than `limit` levels deep in `text` (brackets inside strings not
/// counted). Malformed text may count wrongly here; the parser refuses it afterwards.
bool nested_deeper_than(std::string_view text, int limit) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > limit) return true;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return false;
}

// The depth is checked on the text, before parsing: nlohmann's parser with a callback, which could check it
// as it goes, scans the enclosing array at the end of every object (quadratic: 65,537 glTF nodes took 16 s).
Json parse_json(std::string_view text) {
  if (nested_deeper_than(text, GltfLimits::max_json_depth))
    refuse("glTF JSON is nested deeper than " + std::to_string(GltfLimits::max_json_depth) + " levels");
  try {
    return Json::parse(text.begin(), text.end());
  } catch (const Json::exception& e) {
    refuse(std::string("glTF JSON does not parse: ") + e.what());
  }
}

std::size_t base64_padding(std::string_view payload) {
  std::size_t padding = 0;
  while (padding < payload.size() && payload[payload.size() - 1 - padding] == '=') ++padding;
  return padding;
}

bool is_base64_payload(std::string_view payload) {
  if (payload.size() % 4 != 0) return false;
  const std::size_t padding = base64_padding(payload);
  if (padding > 2) return false;
  for (std::size_t i = 0; i + padding < payload.size(); ++i) {
    const char c = payload[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' || c == '/'))
      return false;
  }
  return true;
}

// Of a payload that is_base64_payload accepted.
std::size_t base64_decoded_size(std::string_view payload) {
  return payload.size() / 4 * 3 - base64_padding(payload);
}

// Component count of an accessor type; 0 for an unknown one.
std::uint64_t components(const std::string& type) {
  constexpr std::array<std::pair<const char*, std::uint64_t>, 7> kTypes{
      {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT2", 4}, {"MAT3", 9}, {"MAT4", 16}}};
  for (const auto& [name, count] : kTypes)
    if (type == name) return count;
  return 0;
}

// Bytes of a glTF 2.0 component type; 0 for an unknown one.
std::uint64_t component_bytes(std::uint64_t component_type) {
  switch (component_type) {
    case 5120:  // BYTE
    case 5121:  // UNSIGNED_BYTE
      return 1;
    case 5122:  // SHORT
    case 5123:  // UNSIGNED_SHORT
      return 2;
    case 5125:  // UNSIGNED_INT
    case 5126:  // FLOAT
      return 4;
    default:
      return 0;
  }
}

constexpr const char* kModeNames[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                      "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};

// Builds the reduced document while checking what it keeps. Arrays keep their input length (entries that are
// not read become null, which assimp never looks at), so every index stays valid as it is.
class Reducer {
 public:
  Reducer(const Json& doc, std::optional<std::string_view> bin, bool binary,
          const std::optional<std::string>& asset_directory)
      : doc_(doc), bin_(bin), binary_(binary), asset_directory_(asset_directory) {}

  ReducedGltf run() {
    check_asset();
    const std::vector<std::size_t> roots = scene_roots();
    walk_nodes(roots);
    Json out = {{"asset", {{"version", "2.0"}}},
                {"scene", 0},
                {"scenes", Json::array({Json::object({{"nodes", roots}})})},
                {"nodes", std::move(nodes_.out)},
                {"meshes", std::move(meshes_.out)},
                {"accessors", std::move(accessors_.out)},
                {"bufferViews", std::move(views_.out)},
                {"buffers", std::move(buffers_.out)}};
    result_.bytes = out.dump();
    result_.format = binary_ ? "glb" : "gltf";
    if (binary_) result_.bytes = as_glb(result_.bytes);
    return std::move(result_);
  }

 private:
  // One top-level array: the input's entries and the reduced ones.
  struct Section {
    explicit Section(const char* section_name) : name(section_name) {}
    const char* name;
    const Json* in = nullptr;
    Json out = Json::array();
    std::vector<char> done;
  };

  void open(Section& section) {
    if (section.in != nullptr) return;
    static const Json kEmpty = Json::array();
    const auto it = doc_.find(section.name);
    if (it != doc_.end() && !it->is_array())
      refuse(std::string("glTF '") + section.name + "' is not an array");
    section.in = it == doc_.end() ? &kEmpty : &*it;
    section.out = Json::array();
    section.out.get_ref<Json::array_t&>().resize(section.in->size());
    section.done.assign(section.in->size(), 0);
  }

  // Entry `index` of `section`, checked to exist and to be an object.
  const Json& entry(Section& section, std::uint64_t index, const std::string& referrer) {
    open(section);
    if (index >= section.in->size())
      refuse(referrer + " refers to " + where(section, index) + ", which does not exist");
    const Json& e = (*section.in)[index];
    if (!e.is_object()) refuse(where(section, index) + " is not an object");
    return e;
  }

  static std::string where(const Section& section, std::uint64_t index) {
    return std::string(section.name) + "[" + std::to_string(index) + "]";
  }

  // A member the schema types as a non-negative integer; nullopt when absent.
  static std::optional<std::uint64_t> unsigned_member(const Json& object, const char* key,
                                                      const std::string& owner) {
    const auto it = object.find(key);
    if (it == object.end()) return std::nullopt;
    if (!it->is_number_unsigned()) refuse(owner + ": '" + key + "' is not a non-negative integer");
    return it->get<std::uint64_t>();
  }

  static std::uint64_t required_unsigned(const Json& object, const char* key, const std::string& owner) {
    const auto value = unsigned_member(object, key, owner);
    if (!value) refuse(owner + " has no '" + key + "'");
    return *value;
  }

  void check_asset() {
    if (!doc_.is_object()) refuse("glTF JSON is not an object");
    const auto asset = doc_.find("asset");
    if (asset == doc_.end() || !asset->is_object() || !asset->contains("version") ||
        !(*asset)["version"].is_string())
      refuse("no asset.version: not a glTF file?");
    const std::string version = (*asset)["version"].get<std::string>();
    if (version.rfind("2.", 0) != 0) refuse("glTF version '" + version + "' is not read (only 2.x)");
    // A required extension that the loader does not know may change the geometry or how it is stored
    // (compression, quantisation, instancing): the glTF rules say such a file must not be read without it.
    const auto required = doc_.find("extensionsRequired");
    if (required == doc_.end()) return;
    if (!required->is_array()) refuse("glTF 'extensionsRequired' is not an array");
    for (const Json& name : *required) {
      if (!name.is_string()) refuse("glTF 'extensionsRequired' holds a non-string");
      const std::string extension = name.get<std::string>();
      const bool appearance_only =
          extension.rfind("KHR_materials_", 0) == 0 || extension.rfind("KHR_texture_", 0) == 0 ||
          extension.rfind("EXT_texture_", 0) == 0 || extension == "KHR_lights_punctual";
      if (!appearance_only) refuse("glTF requires the extension " + extension + ", which is not read");
    }
  }

  std::vector<std::size_t> scene_roots() {
    Section scenes{"scenes"};
    open(scenes);
    if (scenes.in->empty()) refuse("glTF has no scene: nothing to read");
    const std::uint64_t scene = unsigned_member(doc_, "scene", "glTF").value_or(0);
    const Json& s = entry(scenes, scene, "glTF 'scene'");
    std::vector<std::size_t> roots;
    if (const auto nodes = s.find("nodes"); nodes != s.end()) {
      if (!nodes->is_array()) refuse(where(scenes, scene) + ": 'nodes' is not an array");
      for (const Json& n : *nodes) {
        if (!n.is_number_unsigned()) refuse(where(scenes, scene) + ": a node index is not an integer");
        roots.push_back(n.get<std::size_t>());
      }
    }
    return roots;
  }

  // Depth-first over the scene's trees, without recursion. A node reached twice (shared by two parents,
  // listed twice, or in a cycle) is refused: glTF nodes form disjoint trees, and assimp would expand shared
  // subtrees once per path (exponentially many) or recurse forever.
  void walk_nodes(const std::vector<std::size_t>& roots) {
    open(nodes_);
    std::vector<std::pair<std::uint64_t, std::size_t>> pending;  // node, depth
    auto reach = [&](std::uint64_t node, std::size_t depth, const std::string& referrer) {
      entry(nodes_, node, referrer);
      if (nodes_.done[node])
        refuse(where(nodes_, node) + " is reached twice from the scene (nodes must form trees)");
      if (depth > GltfLimits::max_node_depth)
        refuse("glTF node trees deeper than " + std::to_string(GltfLimits::max_node_depth) +
               " levels are not read");
      nodes_.done[node] = 1;
      pending.emplace_back(node, depth);
    };
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) reach(*it, 1, "the scene");
    while (!pending.empty()) {
      const auto [node, depth] = pending.back();
      pending.pop_back();
      const Json& in = (*nodes_.in)[node];
      const std::string owner = where(nodes_, node);
      Json out = Json::object();
      if (const auto name = in.find("name"); name != in.end() && name->is_string()) out["name"] = *name;
      if (const auto mesh = unsigned_member(in, "mesh", owner)) {
        reduce_mesh(*mesh, owner);
        out["mesh"] = *mesh;
      }
      copy_numbers(in, out, "matrix", 16, owner);
      copy_numbers(in, out, "translation", 3, owner);
      copy_numbers(in, out, "rotation", 4, owner);
      copy_numbers(in, out, "scale", 3, owner);
      if (const auto children = in.find("children"); children != in.end()) {
        if (!children->is_array()) refuse(owner + ": 'children' is not an array");
        Json kept = Json::array();
        for (const Json& child : *children) {
          if (!child.is_number_unsigned()) refuse(owner + ": a child index is not a non-negative integer");
          reach(child.get<std::uint64_t>(), depth + 1, owner);
          kept.push_back(child);
        }
        out["children"] = std::move(kept);
      }
      nodes_.out[node] = std::move(out);
    }
  }

  static void copy_numbers(const Json& in, Json& out, const char* key, std::size_t count,
                           const std::string& owner) {
    const auto it = in.find(key);
    if (it == in.end()) return;
    if (!it->is_array() || it->size() != count)
      refuse(owner + ": '" + key + "' is not " + std::to_string(count) + " numbers");
    for (const Json& x : *it)
      if (!x.is_number()) refuse(owner + ": '" + key + "' holds a non-number");
    out[key] = *it;
  }

  void reduce_mesh(std::uint64_t mesh, const std::string& referrer) {
    const Json& in = entry(meshes_, mesh, referrer);
    if (meshes_.done[mesh]) return;
    meshes_.done[mesh] = 1;
    const std::string owner = where(meshes_, mesh);
    const auto primitives = in.find("primitives");
    if (primitives == in.end() || !primitives->is_array()) refuse(owner + " has no 'primitives' array");
    Json out = Json::object();
    if (const auto name = in.find("name"); name != in.end() && name->is_string()) out["name"] = *name;
    Json kept = Json::array();
    for (std::size_t p = 0; p < primitives->size(); ++p) {
      const Json& primitive = (*primitives)[p];
      const std::string prim = owner + ".primitives[" + std::to_string(p) + "]";
      if (!primitive.is_object()) refuse(prim + " is not an object");
      const std::uint64_t mode = unsigned_member(primitive, "mode", prim).value_or(4);
      if (mode > 6) refuse(prim + ": mode " + std::to_string(mode) + " is not a glTF primitive mode");
      const auto attributes = primitive.find("attributes");
      if (attributes == primitive.end() || !attributes->is_object())
        refuse(prim + " has no 'attributes' object");
      const auto position = unsigned_member(*attributes, "POSITION", prim + ".attributes");
      if (!position) refuse(prim + " has no POSITION attribute");
      const std::uint64_t vertices = reduce_accessor(*position, Role::positions, prim);
      const auto indices = unsigned_member(primitive, "indices", prim);
      const std::uint64_t elements = indices ? reduce_accessor(*indices, Role::indices, prim) : vertices;
      // assimp 5.2 reads line loops and strips unsafely (a loop whose first segment has a bad index makes it
      // dereference null), and strips or fans of fewer than three elements past their face array. None of
      // these holds a triangle, so they are left out as the loader leaves out all points and lines.
      const bool no_triangle = (mode == 5 || mode == 6) && elements < 3;
      if (mode == 2 || mode == 3 || no_triangle) {
        result_.warnings.push_back(prim + " (" + kModeNames[mode] + ", " + std::to_string(elements) +
                                   " elements) left out: it holds no triangle");
        if (mode == 2) result_.dropped_line_segments += elements;
        if (mode == 3 && elements > 0) result_.dropped_line_segments += elements - 1;
        continue;
      }
      Json reduced = {{"attributes", {{"POSITION", *position}}}, {"mode", mode}};
      if (indices) reduced["indices"] = *indices;
      kept.push_back(std::move(reduced));
    }
    out["primitives"] = std::move(kept);
    meshes_.out[mesh] = std::move(out);
  }

  enum class Role { positions, indices };

  // Checks accessor `a` for its role and that all its elements lie inside its buffer view; returns its count.
  std::uint64_t reduce_accessor(std::uint64_t a, Role role, const std::string& referrer) {
    const Json& in = entry(accessors_, a, referrer);
    const std::string owner = where(accessors_, a);
    const std::uint64_t count = required_unsigned(in, "count", owner);
    if (in.contains("sparse")) refuse(owner + " is sparse: sparse accessors are not read");
    const auto view = unsigned_member(in, "bufferView", owner);
    if (!view) refuse(owner + " has no bufferView (its data is missing, or compressed)");
    const std::uint64_t component_type = required_unsigned(in, "componentType", owner);
    const std::uint64_t bytes = component_bytes(component_type);
    if (bytes == 0)
      refuse(owner + ": componentType " + std::to_string(component_type) + " is not a glTF 2.0 type");
    const auto type = in.find("type");
    if (type == in.end() || !type->is_string() || components(type->get<std::string>()) == 0)
      refuse(owner + " has no valid 'type'");
    const std::string type_name = type->get<std::string>();
    if (role == Role::positions && (component_type != 5126 || type_name != "VEC3"))
      refuse(owner + " holds positions that are not float VEC3 (quantised positions are not read)");
    if (role == Role::indices &&
        (type_name != "SCALAR" ||
         (component_type != 5121 && component_type != 5123 && component_type != 5125)))
      refuse(owner + " holds indices that are not unsigned integer scalars");
    if (count < 1 || count > 0xFFFFFFFFu)
      refuse(owner + ": count " + std::to_string(count) + " is out of range");
    const std::uint64_t offset = unsigned_member(in, "byteOffset", owner).value_or(0);
    const View v = reduce_view(*view, owner);
    const std::uint64_t element = bytes * components(type_name);
    const std::uint64_t stride = v.stride != 0 ? v.stride : element;
    if (stride < element)
      refuse(owner + ": its elements (" + std::to_string(element) +
             " bytes) overlap in a view with byteStride " + std::to_string(stride));
    // count <= 2^32 - 1 and stride <= 252: no overflow.
    if (offset > v.length || (count - 1) * stride + element > v.length - offset)
      refuse(owner + ": " + std::to_string(count) + " elements from byteOffset " + std::to_string(offset) +
             " run past the end of " + where(views_, *view) + " (" + std::to_string(v.length) + " bytes)");
    if (accessors_.done[a]) return count;
    accessors_.done[a] = 1;
    accessors_.out[a] = {{"bufferView", *view},
                         {"byteOffset", offset},
                         {"componentType", component_type},
                         {"count", count},
                         {"type", type_name}};
    return count;
  }

  struct View {
    std::uint64_t length;
    std::uint64_t stride;  // 0: tightly packed
  };

  View reduce_view(std::uint64_t v, const std::string& referrer) {
    const Json& in = entry(views_, v, referrer);
    const std::string owner = where(views_, v);
    const std::uint64_t length = required_unsigned(in, "byteLength", owner);
    const std::uint64_t stride = unsigned_member(in, "byteStride", owner).value_or(0);
    if (views_.done[v]) return {length, stride};
    if (length < 1) refuse(owner + ": byteLength is 0");
    if (in.contains("byteStride") && (stride < 4 || stride > 252 || stride % 4 != 0))
      refuse(owner + ": byteStride " + std::to_string(stride) + " is not a multiple of 4 in [4, 252]");
    const std::uint64_t offset = unsigned_member(in, "byteOffset", owner).value_or(0);
    const std::uint64_t buffer = required_unsigned(in, "buffer", owner);
    const std::uint64_t size = reduce_buffer(buffer, owner);
    if (offset > size || length > size - offset)
      refuse(owner + ": bytes " + std::to_string(offset) + " + " + std::to_string(length) +
             " run past the end of " + where(buffers_, buffer) + " (" + std::to_string(size) + " bytes)");
    views_.done[v] = 1;
    Json out = {{"buffer", buffer}, {"byteOffset", offset}, {"byteLength", length}};
    if (stride != 0) out["byteStride"] = stride;
    views_.out[v] = std::move(out);
    return {length, stride};
  }

  // Checks buffer `b` and returns its size, which assimp will have in memory: a GLB's BIN chunk, a base64
  // data URI (decoded), or a file (assimp refuses one shorter than byteLength).
  std::uint64_t reduce_buffer(std::uint64_t b, const std::string& referrer) {
    const Json& in = entry(buffers_, b, referrer);
    const std::string owner = where(buffers_, b);
    const std::uint64_t length = required_unsigned(in, "byteLength", owner);
    if (buffers_.done[b]) return length;
    if (length < 1) refuse(owner + ": byteLength is 0");
    Json out = {{"byteLength", length}};
    const auto uri = in.find("uri");
    if (uri == in.end()) {
      if (!binary_ || b != 0)
        refuse(owner + " has no uri (only the first buffer of a GLB file may lack one)");
      if (!bin_) refuse(owner + " is the GLB's BIN chunk, but the file has none");
      if (length > bin_->size())
        refuse(owner + ": byteLength " + std::to_string(length) + " exceeds the GLB BIN chunk (" +
               std::to_string(bin_->size()) + " bytes)");
    } else {
      if (!uri->is_string()) refuse(owner + ": 'uri' is not a string");
      const std::string& text = uri->get_ref<const std::string&>();
      if (text.rfind("data:", 0) == 0) {
        // assimp parses a data URI's header with 8-bit offsets (a long media type sends them astray), so the
        // reduced file carries a fixed header before the checked payload.
        const std::size_t comma = text.find(',');
        if (comma == std::string::npos || comma < 12 || text.compare(comma - 7, 7, ";base64") != 0)
          refuse(owner + ": only base64 data URIs are read");
        const std::string_view payload = std::string_view(text).substr(comma + 1);
        if (!is_base64_payload(payload)) refuse(owner + ": the data URI is not valid base64");
        if (base64_decoded_size(payload) != length)
          refuse(owner + ": the data URI holds " + std::to_string(base64_decoded_size(payload)) +
                 " bytes, byteLength says " + std::to_string(length));
        out["uri"] = "data:application/octet-stream;base64," + std::string(payload);
      } else {
        if (!asset_directory_)
          refuse(owner + " refers to the file '" + text + "', which a mesh read from memory cannot use");
        if (text.empty() || text.find('\0') != std::string::npos)
          refuse(owner + ": the uri is empty or holds a NUL byte");
        out["uri"] = *asset_directory_ + text;  // as assimp resolves it next to the file
      }
    }
    buffers_.done[b] = 1;
    buffers_.out[b] = std::move(out);
    return length;
  }

  std::string as_glb(const std::string& json) const {
    std::string padded_json = json;
    padded_json.append((4 - padded_json.size() % 4) % 4, ' ');
    std::string bin = bin_ ? std::string(*bin_) : std::string();
    const std::size_t bin_length = bin.size();
    bin.append((4 - bin.size() % 4) % 4, '\0');
    const std::size_t total = 12 + 8 + padded_json.size() + (bin_ ? 8 + bin.size() : 0);
    if (total > 0xFFFFFFFFu) refuse("the GLB file is larger than 4 GB");
    std::string out = "glTF";
    append_u32(out, 2);
    append_u32(out, static_cast<std::uint32_t>(total));
    append_u32(out, static_cast<std::uint32_t>(padded_json.size()));
    append_u32(out, kChunkJson);
    out += padded_json;
    if (bin_) {
      append_u32(out, static_cast<std::uint32_t>(bin_length));
      append_u32(out, kChunkBin);
      out += bin;
    }
    return out;
  }

  const Json& doc_;
  std::optional<std::string_view> bin_;
  bool binary_;
  const std::optional<std::string>& asset_directory_;
  Section nodes_{"nodes"}, meshes_{"meshes"}, accessors_{"accessors"}, views_{"bufferViews"},
      buffers_{"buffers"};
  ReducedGltf result_;
};

}  // namespace

std::optional<ReducedGltf> reduce_gltf(std::string_view input, std::string_view format,
                                       const std::optional<std::string>& asset_directory) {
  const bool binary = format == "glb";
  std::string_view json = input;
  std::optional<std::string_view> bin;
  if (binary) {
    const GlbParts parts = split_glb(input);
    json = parts.json;
    bin = parts.bin;
  } else {
    const std::size_t first = input.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos || input[first] != '{') return std::nullopt;
  }
  const Json doc = parse_json(json);
  return Reducer(doc, bin, binary, asset_directory).run();
}

}  // namespace bvhlab::detail

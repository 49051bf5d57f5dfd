// glTF input (bvh/gltf_reduce.hpp): each malformed or hostile file here made assimp 5.2 crash, write or read
// out of bounds, recurse without bound or hang, until the loader started handing assimp a reduced, checked
// copy. Each is now refused with a message naming the input and the problem, or loads with the unusable part
// left out. Well-formed files of every shape the reducer keeps (GLB and text, strided, instanced, external
// buffer) load as before.
#include "bvh/mesh_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

using Json = nlohmann::json;
namespace fs = std::filesystem;

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t group = 0;
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    for (std::size_t k = 0; k < 3; ++k)
      group = (group << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out.push_back(k <= n ? kAlphabet[(group >> (18 - 6 * k)) & 63] : '=');
  }
  return out;
}

template <class T>
void append(std::string& out, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  out.append(raw, sizeof(T));
}

// A tetrahedron: 4 float positions (48 bytes), then 12 uint16 indices (24 bytes).
std::string tetrahedron_data() {
  std::string data;
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f}) append(data, x);
  for (std::uint16_t i : {0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3}) append(data, i);
  return data;
}

// The tetrahedron as a glTF document; buffer 0 carries `data` as a base64 data URI.
Json tetrahedron(const std::string& data = tetrahedron_data()) {
  return {{"asset", {{"version", "2.0"}}},
          {"scene", 0},
          {"scenes", {{{"nodes", {0}}}}},
          {"nodes", {{{"mesh", 0}}}},
          {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
          {"buffers",
           {{{"byteLength", data.size()}, {"uri", "data:application/octet-stream;base64," + base64(data)}}}},
          {"bufferViews",
           {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
            {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 24}}}},
          {"accessors",
           {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
            {{"bufferView", 1}, {"componentType", 5123}, {"count", 12}, {"type", "SCALAR"}}}}};
}

// `doc` as a GLB file whose buffer 0 is the BIN chunk holding `bin`.
std::string glb(Json doc, const std::string& bin) {
  doc["buffers"][0].erase("uri");
  std::string json = doc.dump();
  json.append((4 - json.size() % 4) % 4, ' ');
  std::string padded = bin;
  padded.append((4 - padded.size() % 4) % 4, '\0');
  std::string out = "glTF";
  append<std::uint32_t>(out, 2);
  append<std::uint32_t>(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + padded.size()));
  append<std::uint32_t>(out, static_cast<std::uint32_t>(json.size()));
  out += "JSON";
  out += json;
  append<std::uint32_t>(out, static_cast<std::uint32_t>(bin.size()));
  out += std::string("BIN\0", 4);
  out += padded;
  return out;
}

LoadedMesh load(const std::string& bytes, const std::string& format, const std::string& name) {
  return load_mesh_from_memory(std::as_bytes(std::span(bytes.data(), bytes.size())), format, name);
}

// Expects a refusal naming `name` and containing `problem`.
void expect_refused(const std::string& bytes, const std::string& format, const std::string& name,
                    const std::string& problem) {
  try {
    load(bytes, format, name);
    ADD_FAILURE() << name << " loaded";
  } catch (const MeshError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(name), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << name << ": " << what;
  }
}

void expect_refused(const Json& doc, const std::string& name, const std::string& problem) {
  expect_refused(doc.dump(), "gltf", name, problem);
}

// The tetrahedron with the value at JSON pointer `pointer` replaced: refused for `problem`.
void expect_refused_with(const char* pointer, const Json& value, const std::string& name,
                         const std::string& problem) {
  Json doc = tetrahedron();
  doc[Json::json_pointer(pointer)] = value;
  expect_refused(doc, name, problem);
}

TEST(BadGltf, WellFormedTetrahedronLoadsAsTextAndAsGlb) {
  for (const auto& [bytes, format] : {std::pair{tetrahedron().dump(), std::string("gltf")},
                                      std::pair{glb(tetrahedron(), tetrahedron_data()), std::string("glb")},
                                      std::pair{tetrahedron().dump(), std::string("")}}) {
    const LoadedMesh loaded = load(bytes, format, "tetra." + format);
    EXPECT_EQ(loaded.mesh.triangle_count(), 4u) << format;
    EXPECT_EQ(loaded.mesh.vertices.size(), 4u) << format;
    EXPECT_EQ(loaded.report.bounds.max, Vec3(1, 1, 1)) << format;
  }
}

// Fuzz finding (fuzz_mesh_load, ten-minute run): a LINE_LOOP whose first segment has an out-of-range index
// made assimp close the loop through a null face (SEGV). Line loops and strips hold no triangle: they are
// left out with a warning, next to the triangles of the same mesh, and counted with the dropped lines.
TEST(BadGltf, LineLoopsAndStripsAreLeftOutNextToTriangles) {
  std::string data = tetrahedron_data();
  for (std::uint16_t i : {900, 901, 0, 1}) append(data, i);  // a loop starting with a bad segment
  Json doc = tetrahedron(data);
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 8}});
  doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5123}, {"count", 4}, {"type", "SCALAR"}});
  auto& primitives = doc["meshes"][0]["primitives"];
  primitives.push_back({{"attributes", {{"POSITION", 0}}}, {"indices", 2}, {"mode", 2}});
  primitives.push_back({{"attributes", {{"POSITION", 0}}}, {"indices", 2}, {"mode", 3}});
  for (const std::string format : {"gltf", "glb"}) {
    const std::string bytes = format == "glb" ? glb(doc, data) : doc.dump();
    const LoadedMesh loaded = load(bytes, format, "lines." + format);
    EXPECT_EQ(loaded.mesh.triangle_count(), 4u);
    EXPECT_EQ(loaded.report.ignored_lines, 4u + 3u);
    std::string warnings;
    for (const auto& w : loaded.report.warnings) warnings += w + "\n";
    EXPECT_NE(warnings.find("LINE_LOOP"), std::string::npos) << warnings;
    EXPECT_NE(warnings.find("LINE_STRIP"), std::string::npos) << warnings;
  }
  // With nothing else in the file, there is nothing to read.
  primitives.erase(primitives.begin());
  expect_refused(doc, "only-lines.gltf", "no triangles");
}

// A TRIANGLE_FAN of two indices made assimp write a face past its zero-length face array; a strip of one
// asked for 2^64 - 1 faces. Neither holds a triangle: left out.
TEST(BadGltf, FansAndStripsWithoutATriangleAreLeftOut) {
  Json doc = tetrahedron();
  doc["accessors"].push_back({{"bufferView", 1}, {"componentType", 5123}, {"count", 2}, {"type", "SCALAR"}});
  doc["accessors"].push_back({{"bufferView", 1}, {"componentType", 5123}, {"count", 1}, {"type", "SCALAR"}});
  auto& primitives = doc["meshes"][0]["primitives"];
  primitives.push_back({{"attributes", {{"POSITION", 0}}}, {"indices", 2}, {"mode", 6}});
  primitives.push_back({{"attributes", {{"POSITION", 0}}}, {"indices", 3}, {"mode", 5}});
  const LoadedMesh loaded = load(doc.dump(), "gltf", "fans.gltf");
  EXPECT_EQ(loaded.mesh.triangle_count(), 4u);
  EXPECT_EQ(loaded.report.warnings.size(), 2u);
  // A fan of three is a triangle and is kept.
  doc["accessors"][2]["count"] = 3;
  primitives.erase(2);
  EXPECT_EQ(load(doc.dump(), "gltf", "fan3.gltf").mesh.triangle_count(), 4u + 1u);  // duplicates are kept
}

// assimp checks an accessor against its view with the component size instead of the element size and
// ignores the accessor's byteOffset when it copies: positions at byteOffset 28 were read 48 bytes past the
// buffer (ASan: heap-buffer-overflow). Every element must now lie inside its view, and the view inside its
// buffer, without overflow.
TEST(BadGltf, AccessorsAndViewsOutsideTheirBufferAreRefused) {
  expect_refused_with("/accessors/0/byteOffset", 28, "offset.gltf", "run past the end of bufferViews[0]");
  expect_refused_with("/accessors/1/count", 13, "count.gltf", "run past the end");
  // offset + length wraps around to 16:
  expect_refused_with("/bufferViews/1/byteOffset", 18446744073709551608ull, "wrap.gltf",
                      "run past the end of buffers[0]");
  expect_refused_with("/bufferViews/0/byteStride", 8, "stride.gltf", "overlap");  // below a VEC3 of floats
  expect_refused_with("/accessors/0/bufferView", 7, "ref.gltf", "bufferViews[7], which does not exist");
  expect_refused_with("/accessors/0/count", 0, "zero.gltf", "count 0");
  // A GLB whose buffer is longer than its BIN chunk.
  Json doc = tetrahedron();
  doc["buffers"][0]["byteLength"] = 200;
  expect_refused(glb(doc, tetrahedron_data()), "glb", "short.glb", "exceeds the GLB BIN chunk");
}

// assimp drops a glTF face with an out-of-range index and only logs it: the loader refuses the file, as it
// does for every format, rather than return a mesh with a hole.
TEST(BadGltf, OutOfRangeIndexIsRefused) {
  std::string data = tetrahedron_data();
  data[48] = 9;  // the first index: vertex 9 of 4
  expect_refused(tetrahedron(data).dump(), "gltf", "bad-index.gltf", "index out of range");
}

// An interleaved (strided) vertex buffer is read as it should be.
TEST(BadGltf, StridedPositionsLoad) {
  std::string data;
  for (int v = 0; v < 4; ++v) {
    for (int k = 0; k < 3; ++k) append(data, static_cast<float>(v == k + 1));
    append(data, 7.f);  // another attribute, interleaved
  }
  for (std::uint16_t i : {0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3}) append(data, i);
  Json doc = tetrahedron(data);
  doc["bufferViews"][0] = {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 64}, {"byteStride", 16}};
  doc["bufferViews"][1]["byteOffset"] = 64;
  const LoadedMesh loaded = load(doc.dump(), "gltf", "strided.gltf");
  EXPECT_EQ(loaded.mesh.triangle_count(), 4u);
  EXPECT_EQ(loaded.report.bounds.max, Vec3(1, 1, 1));
}

// assimp's JSON parser recurses once per nesting level: 200000 levels overflowed its stack (SEGV), with a
// glTF hint or none (assimp then tries JSON input as glTF). With an OBJ hint, only the OBJ reader sees it.
TEST(BadGltf, DeepJsonIsRefused) {
  const std::string deep = R"({"asset": {"version": "2.0"}, "extras": )" + std::string(200000, '[') +
                           std::string(200000, ']') + "}";
  for (const std::string format : {"gltf", ""})
    expect_refused(deep, format, "deep.gltf", "nested deeper than");
  expect_refused(deep, "obj", "deep.obj", "deep.obj: ");
}

// The limit is 64 levels: the root object and 63 arrays inside it load, one array more is refused. Brackets
// inside strings (escaped quotes included) are not nesting.
TEST(BadGltf, JsonNestingIsCountedOutsideStringsUpToTheLimit) {
  const auto nested = [](int arrays, const std::string& text) {
    Json doc = tetrahedron();
    Json extras = Json::array({text});
    for (int level = 1; level < arrays; ++level) extras = Json::array({extras});
    doc["extras"] = extras;
    return doc.dump();
  };
  const std::string brackets = "\\\" " + std::string(100, '[');  // a backslash, a quote, brackets
  EXPECT_EQ(load(nested(63, brackets), "gltf", "deep63.gltf").mesh.triangle_count(), 4u);
  expect_refused(nested(64, brackets), "gltf", "deep64.gltf", "nested deeper than 64 levels");
}

// Nodes must form trees. Two children lists naming the same node 40 times over made assimp build 2^40
// nodes (killed); a cycle, a root listed twice, or a chain deeper than assimp's recursion can take are
// refused too.
TEST(BadGltf, NodeGraphsThatAreNotTreesAreRefused) {
  Json doc = tetrahedron();
  doc["nodes"] = Json::array();
  for (int i = 0; i < 40; ++i) doc["nodes"].push_back({{"children", {i + 1, i + 1}}});
  doc["nodes"].push_back({{"mesh", 0}});
  expect_refused(doc, "dag.gltf", "reached twice");
  expect_refused_with("/nodes", {{{"children", {1}}}, {{"children", {0}}, {"mesh", 0}}}, "cycle.gltf",
                      "nodes[0] is reached twice");
  expect_refused_with("/scenes/0/nodes", {0, 0}, "twice.gltf", "reached twice");
  doc = tetrahedron();
  doc["nodes"] = Json::array();
  for (int i = 0; i < 300; ++i) doc["nodes"].push_back({{"children", {i + 1}}});
  doc["nodes"].push_back({{"mesh", 0}});
  expect_refused(doc, "chain.gltf", "deeper than 256");
  // A chain well within the limit loads, with every node's translation applied.
  doc["nodes"] = Json::array();
  for (int i = 0; i < 100; ++i) doc["nodes"].push_back({{"children", {i + 1}}, {"translation", {1, 0, 0}}});
  doc["nodes"].push_back({{"mesh", 0}});
  EXPECT_EQ(load(doc.dump(), "gltf", "chain100.gltf").report.bounds.max.x(), 101.0);
}

// Instancing multiplies faces: 65537 nodes placing one mesh of 65536 triangles (a 1 MB file) would make a
// mesh of 2^32 + 65536 triangles, more than its 32-bit indices hold (and about 50 GB). Refused before
// merging.
TEST(BadGltf, InstancingBeyondTheTriangleLimitIsRefusedUpFront) {
  std::string data;
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) append(data, x);
  for (int t = 0; t < 65536; ++t) data += std::string("\0\1\2", 3);  // uint8 indices
  Json doc = tetrahedron(data);
  doc["bufferViews"][0]["byteLength"] = 36;
  doc["bufferViews"][1] = {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 3 * 65536}};
  doc["accessors"][0]["count"] = 3;
  doc["accessors"][1] = {
      {"bufferView", 1}, {"componentType", 5121}, {"count", 3 * 65536}, {"type", "SCALAR"}};
  doc["nodes"] = Json::array();
  doc["scenes"][0]["nodes"] = Json::array();
  for (int n = 0; n < 65537; ++n) {
    doc["nodes"].push_back({{"mesh", 0}});
    doc["scenes"][0]["nodes"].push_back(n);
  }
  expect_refused(doc, "instances.gltf", "the scene places 4295032832 faces");
}

// A skin without inverseBindMatrices made assimp dereference null; animation samplers with short outputs
// were read past their end. Neither is part of the rigid geometry: the loader does not give them to assimp.
TEST(BadGltf, SkinsAndAnimationsAreNotRead) {
  Json doc = tetrahedron();
  doc["nodes"][0]["skin"] = 0;
  doc["skins"] = Json::array({Json{{"joints", {0}}}});
  const Json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}};
  const Json sampler = {{"input", 1}, {"output", 0}, {"interpolation", "CUBICSPLINE"}};
  doc["animations"] =
      Json::array({Json{{"channels", Json::array({channel})}, {"samplers", Json::array({sampler})}}});
  EXPECT_EQ(load(doc.dump(), "gltf", "skinned.gltf").mesh.triangle_count(), 4u);
}

TEST(BadGltf, WhatTheLoaderCannotReadFaithfullyIsRefused) {
  expect_refused_with("/asset/version", "1.0", "v1.gltf", "version '1.0' is not read");
  expect_refused_with("/extensionsRequired", {"KHR_draco_mesh_compression"}, "draco.gltf",
                      "requires the extension KHR_draco_mesh_compression");
  Json doc = tetrahedron();
  doc["extensionsRequired"] = {"KHR_materials_unlit"};  // appearance only: read
  EXPECT_EQ(load(doc.dump(), "gltf", "unlit.gltf").mesh.triangle_count(), 4u);
  expect_refused_with("/accessors/0/sparse", {{"count", 1}}, "sparse.gltf", "sparse accessors are not read");
  expect_refused_with("/accessors/0/componentType", 5123, "quantised.gltf", "not float VEC3");
  expect_refused_with("/accessors/1/componentType", 5126, "float-indices.gltf",
                      "not unsigned integer scalars");
  expect_refused_with("/meshes/0/primitives/0/mode", 7, "mode.gltf", "mode 7 is not a glTF primitive mode");
  expect_refused_with("/buffers/0/uri", "data:text/plain,abc", "raw-uri.gltf",
                      "only base64 data URIs are read");
  expect_refused_with("/buffers/0/byteLength", 71, "length.gltf", "holds 72 bytes, byteLength says 71");
  expect_refused_with("/buffers/0/uri", "tetra.bin", "external.gltf",
                      "which a mesh read from memory cannot use");
  expect_refused(R"({"asset": {"version": "2.0"}, "scenes": [)", "gltf", "cut.gltf", "does not parse");
  expect_refused("{\"asset\": {}}", "", "noversion.gltf", "no asset.version");
}

TEST(BadGltf, BrokenGlbContainersAreRefused) {
  const std::string good = glb(tetrahedron(), tetrahedron_data());
  expect_refused(good.substr(0, good.size() - 4), "glb", "cut.glb", "(truncated or corrupt?)");
  std::string v1 = good;
  v1[4] = 1;
  expect_refused(v1, "glb", "v1.glb", "binary glTF version 1 is not read");
  std::string json_too_long = good;
  json_too_long[13] = 0x7F;  // JSON chunk length far beyond the file
  expect_refused(json_too_long, "glb", "json.glb", "runs past the end of the file");
  expect_refused(tetrahedron().dump(), "glb", "text.glb", "no glTF header");
}

// From a file, an external buffer is read next to it, as assimp resolves it.
TEST(BadGltf, ExternalBufferNextToTheFileLoads) {
  const fs::path dir = fs::temp_directory_path() / ("bvhlab-gltf-" + std::to_string(getpid()));
  fs::create_directories(dir);
  Json doc = tetrahedron();
  doc["buffers"][0]["uri"] = "tetra.bin";
  std::ofstream(dir / "tetra.gltf") << doc.dump();
  std::ofstream(dir / "tetra.bin", std::ios::binary) << tetrahedron_data();
  EXPECT_EQ(load_mesh(dir / "tetra.gltf").mesh.triangle_count(), 4u);
  fs::remove(dir / "tetra.bin");
  try {
    load_mesh(dir / "tetra.gltf");
    ADD_FAILURE() << "loaded without its buffer";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("tetra.gltf"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bvhlab

#include "bvh/io/ply_internal.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <system_error>

namespace bvhlab::io {

std::optional<PlyScalar> ply_scalar(std::string_view type) {
  struct Entry {
    std::string_view name, sized_name;
    PlyScalar scalar;
  };
  static constexpr Entry kTypes[] = {
      {"char", "int8", {1, false, true}},    {"uchar", "uint8", {1, false, false}},
      {"short", "int16", {2, false, true}},  {"ushort", "uint16", {2, false, false}},
      {"int", "int32", {4, false, true}},    {"uint", "uint32", {4, false, false}},
      {"float", "float32", {4, true, true}}, {"double", "float64", {8, true, true}},
  };
  for (const Entry& e : kTypes)
    if (type == e.name || type == e.sized_name) return e.scalar;
  return std::nullopt;
}

std::optional<PlyFormat> ply_format(std::string_view name) {
  if (name == "ascii") return PlyFormat::Ascii;
  if (name == "binary_little_endian") return PlyFormat::BinaryLittleEndian;
  if (name == "binary_big_endian") return PlyFormat::BinaryBigEndian;
  return std::nullopt;
}

std::optional<std::uint64_t> whole_count(std::string_view text) {
  std::uint64_t count = 0;
  const char* last = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), last, count);
  if (ec != std::errc() || ptr != last) return std::nullopt;
  return count;
}

std::uint64_t leading_count(std::string_view text) {
  std::uint64_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') break;
    value = std::min<std::uint64_t>(value * 10 + static_cast<unsigned>(c - '0'), 1ull << 62);
  }
  return value;
}

const PlyElement* PlyHeader::find(std::string_view name) const {
  for (auto e = elements.rbegin(); e != elements.rend(); ++e)
    if (e->name == name) return &*e;
  return nullptr;
}

bool PlyHeaderLines::next() {
  std::string_view line;
  if (!lines_.next(line)) return false;
  words_ = split_words(line);
  return true;
}

// ---------------------------------------------------------------------------------------------------------
// The header, as assimp 5.2's reader takes it.

namespace {

using Words = std::vector<std::string>;

/// Word `i` of a line, "" when the line has fewer words.
std::string word(const Words& w, std::size_t i) {
  return i < w.size() ? w[i] : std::string();
}

bool all_digits(std::string_view text) {
  return text.find_first_not_of("0123456789") == std::string_view::npos;
}

std::string take_assimp_property(const Words& w, PlyHeader& h) {
  if (h.elements.empty()) return "PLY header: property before any element";
  const std::string type = word(w, 1);
  PlyProperty property;
  if (type == "list") {
    const std::string count_type = word(w, 2), value_type = word(w, 3);
    const auto count = ply_scalar(count_type), value = ply_scalar(value_type);
    if (!count || !value)
      return "PLY header: list property of unknown types '" + count_type + "' '" + value_type + "'";
    property = {word(w, 4), *value, count};
  } else if (const auto value = ply_scalar(type)) {
    property = {word(w, 2), *value, std::nullopt};
  } else {
    return "PLY header: unknown property type '" + type + "'";
  }
  h.elements.back().properties.push_back(std::move(property));
  return {};
}

/// Takes in one non-blank header line before end_header; returns the problem, "" when none.
std::string take_assimp_line(const Words& w, PlyHeader& h) {
  const std::string& keyword = w[0];
  if (keyword == "format") {
    // A bare `format` line keeps the format read before, as this check has always let it (the stream it read
    // with left the word unchanged). Only a first one is refused, as unknown.
    if (w.size() < 2 && h.format) return {};
    const std::string name = word(w, 1);
    h.format = ply_format(name);
    return h.format ? std::string() : "PLY header: unknown format '" + name + "'";
  }
  if (keyword == "element") {
    if (w.size() < 3 || !all_digits(w[2])) return "PLY header: element line without a name and a count";
    h.elements.push_back({w[1], leading_count(w[2]), {}});
    return {};
  }
  if (keyword == "property") return take_assimp_property(w, h);
  if (keyword != "comment" && keyword != "obj_info" && lower_case(keyword) != "ply")
    return "PLY header: unknown line '" + keyword + "'";
  return {};
}

PlyHeaderRead read_assimp_header(std::string_view text) {
  PlyHeaderRead read;
  PlyHeaderLines lines(text);
  while (lines.next()) {
    const Words& w = lines.words();
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      read.header.body = lines.offset();
      break;
    }
    read.problem = take_assimp_line(w, read.header);
    if (!read.problem.empty()) return read;
  }
  if (read.header.body && !read.header.format) read.problem = "PLY header has no format line";
  return read;
}

// ---------------------------------------------------------------------------------------------------------
// The header, as the point cloud reader takes it. Problems start with "header line <n>: ".

std::string take_cloud_format(const Words& w, PlyHeader& h) {
  if (w.size() != 3) return "bad format line";
  h.format = ply_format(w[1]);
  return h.format ? std::string() : "unknown format '" + w[1] + "'";
}

std::string take_cloud_element(const Words& w, PlyHeader& h) {
  if (w.size() != 3) return "bad element line";
  const bool first = h.elements.empty();
  if (first && w[1] != "vertex") return "the first element is '" + w[1] + "', expected 'vertex'";
  PlyElement element{w[1], 0, {}};
  // Only the vertex count is read, and the face count that tells a mesh from a cloud.
  if (first || w[1] == "face") {
    const auto count = whole_count(w[2]);
    if (!count) return "bad " + w[1] + " count '" + w[2] + "'";
    element.count = *count;
  }
  h.elements.push_back(std::move(element));
  return {};
}

std::string take_cloud_property(const Words& w, PlyHeader& h) {
  if (h.elements.empty()) return "a property before any element";
  if (h.elements.size() > 1) return {};  // later elements are not read
  if (w.size() >= 2 && w[1] == "list") return "a list property in the vertex element";
  if (w.size() != 3) return "bad property line";
  const auto value = ply_scalar(w[1]);
  if (!value) return "unknown property type '" + w[1] + "'";
  h.elements.back().properties.push_back({w[2], *value, std::nullopt});
  return {};
}

/// Takes in one header line after the first; returns the problem, "" when none.
std::string take_cloud_line(const Words& w, PlyHeader& h) {
  if (w.empty() || w[0] == "comment" || w[0] == "obj_info") return {};
  if (w[0] == "format") return take_cloud_format(w, h);
  if (w[0] == "element") return take_cloud_element(w, h);
  if (w[0] == "property") return take_cloud_property(w, h);
  return "unknown keyword '" + w[0] + "'";
}

PlyHeaderRead read_cloud_header(std::string_view text) {
  PlyHeaderRead read;
  PlyHeaderLines lines(text);
  if (!lines.next() || lines.words() != Words{"ply"}) {
    read.problem = "not a PLY file (the first line is not 'ply')";
    return read;
  }
  while (!read.header.body) {
    if (!lines.next()) {
      read.problem = "the header has no end_header";
      return read;
    }
    if (!lines.words().empty() && lines.words()[0] == "end_header") {
      read.header.body = lines.offset();
    } else if (std::string problem = take_cloud_line(lines.words(), read.header); !problem.empty()) {
      read.problem = "header line " + std::to_string(lines.number()) + ": " + problem;
      return read;
    }
  }
  if (!read.header.format)
    read.problem = "the header has no format line";
  else if (read.header.elements.empty())
    read.problem = "the header declares no vertex element";
  return read;
}

}  // namespace

PlyHeaderRead read_ply_header(std::string_view text, PlyGrammar grammar) {
  return grammar == PlyGrammar::Assimp ? read_assimp_header(text) : read_cloud_header(text);
}

// ---------------------------------------------------------------------------------------------------------
// The body.

namespace {

/// An ASCII body read line by line, value by value.
class TextBody {
 public:
  TextBody(std::string_view data, PlyTextSyntax syntax) : data_(data), syntax_(syntax) {}

  enum class Line { Found, End, Blank };
  /// Moves to the next element's line.
  Line next_line() {
    if (at_ >= data_.size()) return Line::End;
    line_end_ = at_;
    while (line_end_ < data_.size() && !is_any(data_[line_end_], syntax_.line_ends)) ++line_end_;
    while (at_ < line_end_ && is_any(data_[at_], syntax_.spaces)) ++at_;
    return at_ < line_end_ ? Line::Found : Line::Blank;
  }
  /// The next value on the line; false when the line has no more.
  bool next_value(std::string_view& token) {
    while (at_ < line_end_ && is_any(data_[at_], syntax_.spaces)) ++at_;
    const std::size_t start = at_;
    while (at_ < line_end_ && !is_any(data_[at_], syntax_.spaces)) ++at_;
    token = data_.substr(start, at_ - start);
    return !token.empty();
  }
  /// Characters left on the line.
  [[nodiscard]] std::size_t left_on_line() const { return line_end_ - at_; }
  /// Moves past the line's end.
  void end_line() {
    at_ = line_end_;
    if (at_ < data_.size())
      at_ += data_[at_] == '\r' && at_ + 1 < data_.size() && data_[at_ + 1] == '\n' ? 2 : 1;
  }

 private:
  static bool is_any(char c, std::string_view set) { return set.find(c) != std::string_view::npos; }

  std::string_view data_;
  PlyTextSyntax syntax_;
  std::size_t at_ = 0, line_end_ = 0;
};

/// A binary body read value by value.
class BinaryBody {
 public:
  BinaryBody(std::string_view data, bool big_endian) : data_(data), big_endian_(big_endian) {}
  [[nodiscard]] std::size_t left() const { return data_.size() - at_; }
  void skip(std::uint64_t bytes) { at_ += bytes; }
  /// The next `bytes` bytes as an unsigned integer in the body's byte order.
  std::uint64_t next_unsigned(std::size_t bytes) {
    std::uint64_t value = 0;
    for (std::size_t b = 0; b < bytes; ++b) {
      const std::size_t byte = big_endian_ ? b : bytes - 1 - b;
      value = (value << 8) | static_cast<unsigned char>(data_[at_ + byte]);
    }
    at_ += bytes;
    return value;
  }
  double next_value(const PlyScalar& type) {
    const std::uint64_t bits = next_unsigned(type.bytes);
    if (type.is_float)
      return type.bytes == 4 ? double(std::bit_cast<float>(std::uint32_t(bits)))
                             : std::bit_cast<double>(bits);
    if (!type.is_signed) return double(bits);
    const int shift = 64 - 8 * int(type.bytes);  // sign-extends from the type's width
    return double(std::int64_t(bits << shift) >> shift);
  }

 private:
  std::string_view data_;
  bool big_endian_;
  std::size_t at_ = 0;
};

/// Why reading one element instance stopped, and a list's count.
struct InstanceStop {
  PlyStop kind;
  std::uint64_t list_count = 0;
};

/// Steps over one list on an ASCII line, its count already read; `count` values must follow.
std::optional<InstanceStop> skip_text_list(TextBody& body, std::uint64_t count) {
  // Each value needs at least one character and a separator on this line.
  if (count > body.left_on_line() / 2 + 1) return InstanceStop{PlyStop::ListTooLong, count};
  std::string_view token;
  for (std::uint64_t k = 0; k < count; ++k)
    if (!body.next_value(token)) return InstanceStop{PlyStop::ListTooLong, count};
  return std::nullopt;
}

/// One element instance of an ASCII body, its line included; `values` is null when they are not read.
std::optional<InstanceStop> read_text_instance(TextBody& body, const PlyElement& element,
                                               const PlyBodyRules& rules, std::vector<double>* values) {
  if (const auto line = body.next_line(); line != TextBody::Line::Found)
    return InstanceStop{line == TextBody::Line::End ? PlyStop::DataEnds : PlyStop::BlankLine};
  std::string_view token;
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    if (!body.next_value(token)) return InstanceStop{PlyStop::TooFewValues};
    if (element.properties[p].list_count) {
      const std::uint64_t count = leading_count(token);
      if (auto stop = skip_text_list(body, count)) return stop;
      if (values) (*values)[p] = double(count);
    } else if (values) {
      const auto number = parse_number(token);
      if (!number) return InstanceStop{PlyStop::NotANumber};
      (*values)[p] = *number;
    }
  }
  if (rules.whole_lines && body.next_value(token)) return InstanceStop{PlyStop::ExtraValues};
  body.end_line();
  return std::nullopt;
}

/// One element instance of a binary body; `values` is null when they are not read.
std::optional<InstanceStop> read_binary_instance(BinaryBody& body, const PlyElement& element,
                                                 std::vector<double>* values) {
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    const PlyProperty& property = element.properties[p];
    if (!property.list_count) {
      if (body.left() < property.value.bytes) return InstanceStop{PlyStop::DataEnds};
      if (values)
        (*values)[p] = body.next_value(property.value);
      else
        body.skip(property.value.bytes);
      continue;
    }
    if (body.left() < property.list_count->bytes) return InstanceStop{PlyStop::DataEnds};
    // Read as unsigned: a negative count is as impossible as a huge one.
    const std::uint64_t count = body.next_unsigned(property.list_count->bytes);
    if (count > body.left() / property.value.bytes) return InstanceStop{PlyStop::ListTooLong, count};
    body.skip(count * property.value.bytes);
    if (values) (*values)[p] = double(count);
  }
  return std::nullopt;
}

}  // namespace

std::optional<PlyBodyStop> walk_ply_body(std::string_view text, const PlyHeader& header,
                                         const PlyBodyRules& rules, const PlyRecord& record) {
  const std::string_view data = text.substr(std::min(header.body.value_or(text.size()), text.size()));
  const bool ascii = header.format.value_or(PlyFormat::Ascii) == PlyFormat::Ascii;
  TextBody text_body(data, rules.text);
  BinaryBody binary_body(data, header.format == PlyFormat::BinaryBigEndian);
  std::vector<double> values;
  const std::size_t elements = std::min(rules.elements, header.elements.size());
  for (std::size_t e = 0; e < elements; ++e) {
    const PlyElement& element = header.elements[e];
    if (element.properties.empty()) continue;
    values.resize(element.properties.size());
    std::vector<double>* read = record ? &values : nullptr;
    for (std::uint64_t i = 0; i < element.count; ++i) {
      const auto stop = ascii ? read_text_instance(text_body, element, rules, read)
                              : read_binary_instance(binary_body, element, read);
      if (stop) return PlyBodyStop{stop->kind, e, i, stop->list_count};
      if (record) record(e, values);
    }
  }
  return std::nullopt;
}

}  // namespace bvhlab::io

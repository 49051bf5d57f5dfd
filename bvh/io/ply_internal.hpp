// Internal to the loaders (bvh/io/), not installed: the one PLY reader. The point cloud loader reads a file's
// vertices with it (bvh/io/point_cloud_files.cpp); the mesh loader walks a whole file with it before assimp
// reads the file (bvh/io/format_checks.cpp), so that assimp never meets a body that does not match its
// header.
//
// Both read the header with the same line walk, type and format tables and into the same PlyHeader, and the
// body with the same walk; they differ in the grammar a header must follow (PlyGrammar): the mesh checks take
// what assimp 5.2's reader takes, the cloud reader the grammar bvh/point_cloud.hpp documents (stricter on
// the vertex element, blind to later ones). Each grammar keeps its own messages.
#pragma once

#include "bvh/io/text_internal.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab::io {

/// Where a PLY header must end for the checks that read only the start of a file.
inline constexpr std::size_t kPlyHeaderBytes = 1 << 16;

/// A PLY scalar type: its size in a binary body and how its bytes read.
struct PlyScalar {
  std::size_t bytes = 0;
  bool is_float = false;
  bool is_signed = false;
};
/// The type a header names ("float", "uint8", ...); nullopt for an unknown name.
std::optional<PlyScalar> ply_scalar(std::string_view type);

enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };
/// The body format a `format` line names ("ascii", ...); nullopt for an unknown one.
std::optional<PlyFormat> ply_format(std::string_view name);

/// An element count written as a whole number (digits only) that fits 64 bits; nullopt otherwise.
std::optional<std::uint64_t> whole_count(std::string_view text);
/// A count as assimp reads it: the text's leading digits ("12abc" is 12), saturating far above any real file
/// so that an overflowing count is still caught as huge.
std::uint64_t leading_count(std::string_view text);

struct PlyProperty {
  std::string name;
  PlyScalar value;                      ///< a scalar's type, or the type of a list's values
  std::optional<PlyScalar> list_count;  ///< a list's count type; nullopt for a scalar
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::optional<PlyFormat> format;   ///< nullopt while no format line was read
  std::vector<PlyElement> elements;  ///< in the header's order
  std::optional<std::size_t> body;   ///< offset of the body's first byte; nullopt without an end_header line
  /// The element called `name` declared last, or nullptr.
  [[nodiscard]] const PlyElement* find(std::string_view name) const;
};

/// A header's lines from the first line of a text, each split into words.
class PlyHeaderLines {
 public:
  explicit PlyHeaderLines(std::string_view text) : lines_(text) {}
  /// Reads the next line; false at the end of the text.
  bool next();
  [[nodiscard]] const std::vector<std::string>& words() const { return words_; }
  /// The line's number, 1-based.
  [[nodiscard]] std::size_t number() const { return lines_.number(); }
  /// Where the next line starts: the body, after an end_header line.
  [[nodiscard]] std::size_t offset() const { return lines_.offset(); }

 private:
  LineReader lines_;
  std::vector<std::string> words_;
};

/// The rules a header is read by.
enum class PlyGrammar {
  /// As assimp 5.2's reader takes it: a line whose keyword reads "ply" in any case is skipped wherever it
  /// is; words after those a line needs are ignored; every property is checked, lists included; a count is
  /// its leading digits. Refused: an unknown format, property type or keyword, an element line without a
  /// name and an all-digit count, a property before any element, no format line (once end_header is
  /// found). A bare `format` line after a good one is let through. No end_header is no problem here (the
  /// loader refuses it before).
  Assimp,
  /// As the point cloud reader takes it (bvh/point_cloud.hpp): the first line is "ply", the first element
  /// is `vertex` and has scalar properties only; format, element and property lines have exactly three
  /// words; the vertex and face counts are whole numbers; the properties of later elements are not read.
  PointCloud,
};

/// A header as read.
struct PlyHeaderRead {
  PlyHeader header;     ///< what it declares, up to the first problem
  std::string problem;  ///< the first problem, "" when none
};

/// Reads the header at the start of `text` by `grammar`. Problems are worded as each grammar's reader has
/// always worded them (PointCloud: "header line 3: bad format line"; Assimp: "PLY header: ...").
PlyHeaderRead read_ply_header(std::string_view text, PlyGrammar grammar);

/// How the lines of an ASCII body are split.
struct PlyTextSyntax {
  std::string_view line_ends;  ///< each of these ends a line; CR LF counts as one end
  std::string_view spaces;     ///< these separate the values on a line
};
/// As assimp 5.2 reads a body: lines end at LF, CR LF, CR or NUL; values are separated by spaces, tabs,
/// form feeds and vertical tabs.
inline constexpr PlyTextSyntax kAssimpText{std::string_view("\n\r\0", 3), " \t\f\v"};
/// As the point cloud reader reads one: lines end at LF; values are separated by spaces, tabs and CR.
inline constexpr PlyTextSyntax kCloudText{"\n", " \t\r"};

/// How far and how strictly a body is walked.
struct PlyBodyRules {
  PlyTextSyntax text = kAssimpText;
  /// Only the first this many elements are walked (the cloud reader reads its vertices only).
  std::size_t elements = std::numeric_limits<std::size_t>::max();
  /// ASCII: nothing may follow an element's last value on its line (assimp ignores what does).
  bool whole_lines = false;
};

/// Why a body walk stopped early.
enum class PlyStop {
  DataEnds,      ///< the body ends before the element
  BlankLine,     ///< ASCII: the element's line is blank (assimp would read it as an element)
  TooFewValues,  ///< ASCII: its line holds fewer values than its properties
  NotANumber,    ///< ASCII, values read: a value that is not a number
  ExtraValues,   ///< ASCII, whole lines: more values than its properties
  ListTooLong,   ///< a list's count exceeds what is left of the line (ASCII) or of the body (binary)
};

struct PlyBodyStop {
  PlyStop kind = PlyStop::DataEnds;
  std::size_t element = 0;       ///< index in PlyHeader::elements
  std::uint64_t index = 0;       ///< which of that element's instances
  std::uint64_t list_count = 0;  ///< ListTooLong: the count the list gave
};

/// Receives each element instance's values, one per property in the header's order (a list gives its
/// count).
using PlyRecord = std::function<void(std::size_t element, std::span<const double> values)>;

/// Walks the body of `text` as `header` declares it (header.body must be set), element by element: each
/// value must be there and each list must fit in what is left. Linear in the body and allocating nothing
/// per element; elements without properties take no room. With `record`, values are read (ASCII ones as
/// numbers) and handed over; without, they are only stepped over. Returns where the walk stopped early,
/// nullopt when every element was there.
std::optional<PlyBodyStop> walk_ply_body(std::string_view text, const PlyHeader& header,
                                         const PlyBodyRules& rules, const PlyRecord& record = {});

}  // namespace bvhlab::io

// SPDX-License-Identifier: Apache-2.0
#include "cloud_header.hpp"

#include <array>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "cellmap/common/error.hpp"
#include "cellmap/io/cloud_file.hpp"

namespace cellmap::cloud_header {
namespace {

using Words = std::vector<std::string_view>;
constexpr std::size_t kNone = std::string_view::npos;

[[noreturn]] void refuse(const std::string& reason) {
  throw Error(reason);
}

// Text from the file as it may appear in a one-line message: quoted, printable, at most 40 characters.
std::string shown(std::string_view text) {
  std::string out = "'";
  for (const char c : text.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out + (text.size() > 40 ? "...'" : "'");
}

bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

// What std::istream's >> skips in the classic locale (PCL reads header words with it).
bool is_stream_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}

// The words of a line, split at runs of spaces and tabs as PCL's tokenizers do. Lines with other control
// characters are refused first, so that these words and those of PCL's >> (which also splits at \v, \f, \r)
// are the same.
Words words(std::string_view line) {
  for (const char c : line) {
    if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f) {
      refuse("header line " + shown(line) + " holds a control character");
    }
  }
  Words result;
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && is_blank(line[pos])) ++pos;
    const std::size_t start = pos;
    while (pos < line.size() && !is_blank(line[pos])) ++pos;
    if (pos > start) result.push_back(line.substr(start, pos - start));
  }
  return result;
}

// A decimal integer in [0, max]: digits only (PCL's >> would also take signs, and wrap them).
std::uint64_t integer(std::string_view token, std::uint64_t max, const std::string& what) {
  std::uint64_t value = 0;
  for (const char c : token) {
    const auto digit = static_cast<std::uint64_t>(c - '0');
    if (c < '0' || c > '9' || value > (max - digit) / 10) {
      refuse(what + ": " + shown(token) + " is not an integer in [0, " + std::to_string(max) + "]");
    }
    value = value * 10 + digit;
  }
  if (token.empty()) refuse(what + ": missing value");
  return value;
}

double finite_number(std::string_view token, const std::string& what) {
  const std::string text(token);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value)) {
    refuse(what + ": " + shown(token) + " is not a finite number");
  }
  return value;
}

void expect_words(const Words& w, std::size_t count, const std::string& form) {
  if (w.size() != count) refuse(std::string(w[0]) + ": expected '" + form + "'");
}

// points × bytes per point against the limits shared by both formats; returns the product.
std::uint64_t cloud_bytes(std::uint64_t points, std::uint64_t point_bytes) {
  if (points == 0) refuse("has no points");
  if (point_bytes > kMaxPointBytes) {
    refuse("a point takes " + std::to_string(point_bytes) + " bytes, more than " +
           std::to_string(kMaxPointBytes));
  }
  const std::uint64_t bytes = points * point_bytes;
  if (bytes > kMaxCloudBytes) {
    refuse(std::to_string(points) + " points of " + std::to_string(point_bytes) + " bytes need " +
           std::to_string(bytes) + " bytes, more than " + std::to_string(kMaxCloudBytes));
  }
  return bytes;
}

void expect_data(std::uint64_t needed, std::uint64_t available, const std::string& what) {
  if (needed > available) {
    refuse(what + " need at least " + std::to_string(needed) + " bytes after the header, the file has " +
           std::to_string(available));
  }
}

// ---- PCD

struct PcdField {
  std::string_view name;
  std::uint64_t size = 4;
  char type = 'F';
  std::uint64_t count = 1;
};

enum class PcdData { kAscii, kBinary, kCompressed };

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0;
  std::uint64_t height = 0;
  std::uint64_t points = 0;
  PcdData data = PcdData::kAscii;
  std::size_t data_start = 0;  // offset of the first byte after the DATA line
};

// The keywords in the order PCL writes them (COLUMNS is an old name of FIELDS) and whether each is required.
enum PcdKey { kVersion, kFields, kSize, kType, kCount, kWidth, kHeight, kViewpoint, kPoints, kData };
constexpr std::array<std::string_view, 10> kPcdOrder = {"VERSION", "FIELDS", "SIZE",      "TYPE",   "COUNT",
                                                        "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};
constexpr std::array<bool, 10> kPcdRequired = {false, true, true, true, false, true, true, false, true, true};

int pcd_rank(std::string_view keyword) {
  if (keyword == "COLUMNS") return kFields;
  for (std::size_t i = 0; i < kPcdOrder.size(); ++i) {
    if (kPcdOrder[i] == keyword) return static_cast<int>(i);
  }
  return -1;
}

// One value per field, as SIZE, TYPE and COUNT give them.
Words per_field(const Words& w, const PcdHeader& header) {
  if (w.size() - 1 != header.fields.size()) {
    refuse(std::string(w[0]) + ": " + std::to_string(w.size() - 1) + " values for " +
           std::to_string(header.fields.size()) + " fields");
  }
  return Words(w.begin() + 1, w.end());
}

void read_fields(const Words& w, PcdHeader& header) {
  if (w.size() < 2 || w.size() - 1 > kMaxFields) {
    refuse(std::string(w[0]) + ": expected 1 to " + std::to_string(kMaxFields) + " field names");
  }
  for (std::size_t i = 1; i < w.size(); ++i) {
    for (const PcdField& field : header.fields) {
      if (field.name == w[i]) refuse(std::string(w[0]) + ": field " + shown(w[i]) + " appears twice");
    }
    header.fields.push_back(PcdField{w[i]});
  }
}

void read_types(const Words& values, PcdHeader& header) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    PcdField& field = header.fields[i];
    const std::string_view type = values[i];
    const bool valid = type.size() == 1 && ((type[0] == 'F' && (field.size == 4 || field.size == 8)) ||
                                            type[0] == 'I' || type[0] == 'U');
    if (!valid) {
      refuse("TYPE: " + shown(type) + " of field " + shown(field.name) +
             " is not I, U or F (F: SIZE 4 or 8)");
    }
    field.type = type[0];
  }
}

void read_pcd_line(int rank, const Words& w, PcdHeader& header) {
  const std::string key(w[0]);
  switch (rank) {
    case kFields:
      return read_fields(w, header);
    case kSize: {
      const Words values = per_field(w, header);
      for (std::size_t i = 0; i < values.size(); ++i) {
        const std::uint64_t size = integer(values[i], 8, key);
        if (size != 1 && size != 2 && size != 4 && size != 8)
          refuse(key + ": " + shown(values[i]) + " is not 1, 2, 4 or 8");
        header.fields[i].size = size;
      }
      return;
    }
    case kType:
      return read_types(per_field(w, header), header);
    case kCount: {
      const Words values = per_field(w, header);
      for (std::size_t i = 0; i < values.size(); ++i) {
        header.fields[i].count = integer(values[i], kMaxPointBytes, key);
        if (header.fields[i].count == 0) refuse(key + ": a field's count must be at least 1");
      }
      return;
    }
    case kWidth:
    case kHeight:
    case kPoints: {
      expect_words(w, 2, key + " <integer>");
      const std::uint64_t value = integer(w[1], kMaxCloudPoints, key);
      (rank == kWidth ? header.width : rank == kHeight ? header.height : header.points) = value;
      return;
    }
    case kViewpoint:
      expect_words(w, 8, "VIEWPOINT tx ty tz qw qx qy qz");
      for (std::size_t i = 1; i < w.size(); ++i) (void)finite_number(w[i], key);
      return;
    case kData:
      expect_words(w, 2, "DATA ascii|binary|binary_compressed");
      if (w[1] == "ascii")
        header.data = PcdData::kAscii;
      else if (w[1] == "binary")
        header.data = PcdData::kBinary;
      else if (w[1] == "binary_compressed")
        header.data = PcdData::kCompressed;
      else
        refuse("DATA: " + shown(w[1]) + " is not ascii, binary or binary_compressed");
      return;
    default:
      return;  // kVersion: PCL ignores it
  }
}

void refuse_unterminated(std::string_view head, const std::string& what) {
  refuse(head.size() >= kMaxHeaderBytes
             ? what + " within the first " + std::to_string(kMaxHeaderBytes) + " bytes"
             : what);
}

PcdHeader parse_pcd(std::string_view head) {
  PcdHeader header;
  int last = -1;
  std::size_t pos = 0;
  for (;;) {
    const std::size_t end = head.find('\n', pos);
    if (end == kNone) refuse_unterminated(head, "not a PCD file (no DATA line)");
    std::string_view line = head.substr(pos, end - pos);
    pos = end + 1;
    if (line.empty()) continue;
    if (line.back() == '\r') line.remove_suffix(1);
    const Words w = words(line);
    // PCL stops reading the header at a line of blanks; so do we, with a reason.
    if (w.empty()) refuse("not a PCD file (blank header line before DATA)");
    if (w[0][0] == '#') continue;
    const int rank = pcd_rank(w[0]);
    if (rank < 0) refuse("not a PCD file (unexpected header line " + shown(line) + ")");
    if (rank <= last) refuse(std::string(w[0]) + ": appears twice or out of order");
    for (int missing = last + 1; missing < rank; ++missing) {
      if (kPcdRequired[missing])
        refuse(std::string(kPcdOrder[missing]) + ": missing before " + std::string(w[0]));
    }
    last = rank;
    read_pcd_line(rank, w, header);
    if (rank == kData) {
      header.data_start = pos;
      return header;
    }
  }
}

// After DATA, PCL's header loop goes on while lines are empty or comments, and parses a line whose first word
// starts with a keyword as a header line, whatever the data kind: data that reads so is refused.
void check_data_start(std::string_view head, std::size_t pos, std::uint64_t file_size) {
  static constexpr std::array<std::string_view, 11> kKeywords = {"VERSION",   "FIELDS", "COLUMNS", "SIZE",
                                                                 "TYPE",      "COUNT",  "WIDTH",   "HEIGHT",
                                                                 "VIEWPOINT", "POINTS", "DATA"};
  const bool whole_file = head.size() == file_size;
  while (pos < head.size()) {
    std::size_t end = head.find('\n', pos);
    if (end == kNone) end = head.size();
    const std::string_view line = head.substr(pos, end - pos);
    std::size_t start = 0;
    while (start < line.size() && is_stream_space(line[start])) ++start;
    std::size_t stop = start;
    while (stop < line.size() && !is_stream_space(line[stop])) ++stop;
    const std::string_view word = line.substr(start, stop - start);
    if (pos + stop == head.size() && !whole_file) refuse("cannot tell where the data after DATA starts");
    if (!line.empty() && (word.empty() || word[0] != '#')) {
      for (const std::string_view keyword : kKeywords) {
        if (word.substr(0, keyword.size()) == keyword) {
          refuse("the data after DATA starts with a header keyword (" + shown(word) + ")");
        }
      }
      return;
    }
    pos = end + 1;
  }
}

std::uint32_t little_endian_u32(std::string_view bytes) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i)
    value = (value << 8) | static_cast<unsigned char>(bytes[static_cast<std::size_t>(i)]);
  return value;
}

// binary_compressed: two uint32 (compressed and uncompressed size), then LZF data. PCL sizes its buffers by
// the uncompressed size; LZF expands 3 bytes to at most 264 (88x).
void check_compressed(const PcdHeader& header, std::string_view head, std::uint64_t file_size,
                      std::uint64_t bytes) {
  const std::uint64_t available = file_size - header.data_start;
  expect_data(8, available, "binary_compressed sizes");
  if (header.data_start + 8 > head.size()) refuse("header too long");
  const std::uint64_t compressed = little_endian_u32(head.substr(header.data_start, 4));
  const std::uint64_t uncompressed = little_endian_u32(head.substr(header.data_start + 4, 4));
  if (uncompressed != bytes) {
    refuse("binary_compressed data unpacks to " + std::to_string(uncompressed) + " bytes, the header's " +
           std::to_string(header.points) + " points take " + std::to_string(bytes));
  }
  expect_data(8 + compressed, available,
              "binary_compressed data of " + std::to_string(compressed) + " bytes");
  if (uncompressed > 88 * compressed) {
    refuse("binary_compressed data of " + std::to_string(compressed) + " bytes cannot unpack to " +
           std::to_string(uncompressed));
  }
}

void check_pcd_claims(const PcdHeader& header, std::string_view head, std::uint64_t file_size) {
  bool has_x = false, has_y = false, has_z = false;
  std::uint64_t point_bytes = 0, values = 0;
  for (const PcdField& field : header.fields) {
    has_x |= field.name == "x";
    has_y |= field.name == "y";
    has_z |= field.name == "z";
    point_bytes += field.size * field.count;
    values += field.count;
  }
  if (!has_x || !has_y || !has_z) refuse("has no x, y, z fields");
  if (header.width * header.height != header.points) {
    refuse("WIDTH " + std::to_string(header.width) + " x HEIGHT " + std::to_string(header.height) +
           " is not POINTS " + std::to_string(header.points));
  }
  const std::uint64_t bytes = cloud_bytes(header.points, point_bytes);
  const std::uint64_t available = file_size - header.data_start;
  const std::string points = std::to_string(header.points) + " points";
  if (header.data == PcdData::kAscii) {
    // Each value is at least one character and a separator (the last one's is optional).
    expect_data(header.points * values * 2 - 1, available, points + " in ascii");
  } else if (header.data == PcdData::kBinary) {
    expect_data(bytes, available, points + " of " + std::to_string(point_bytes) + " bytes");
  } else {
    check_compressed(header, head, file_size, bytes);
  }
}

// ---- PLY

struct PlyProperty {
  std::string_view name;
  std::uint64_t min_bytes = 0;  // scalar: its size; list: its count's size (an empty list)
  bool list = false;
};

struct PlyElement {
  std::string_view name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  bool ascii = false;
  std::vector<PlyElement> elements;
  // The cloud's width and height as PCL's reader has them at the end of the header (it sizes the cloud by
  // them): obj_info num_cols / num_rows set them wherever they stand, an "element vertex" line sets them to
  // its count x 1 unless both are set (not 0) already.
  std::uint64_t columns = 0;
  std::uint64_t rows = 0;
  std::size_t data_start = 0;
};

// Bytes of a PLY scalar type, 0 if the name is none.
std::uint64_t ply_type_size(std::string_view type) {
  static constexpr std::array<std::pair<std::string_view, std::uint64_t>, 16> kTypes = {{
      {"char", 1},
      {"int8", 1},
      {"uchar", 1},
      {"uint8", 1},
      {"short", 2},
      {"int16", 2},
      {"ushort", 2},
      {"uint16", 2},
      {"int", 4},
      {"int32", 4},
      {"uint", 4},
      {"uint32", 4},
      {"float", 4},
      {"float32", 4},
      {"double", 8},
      {"float64", 8},
  }};
  for (const auto& [name, size] : kTypes) {
    if (name == type) return size;
  }
  return 0;
}

void read_property(const Words& w, PlyHeader& header) {
  if (header.elements.empty()) refuse("property: before any element");
  PlyElement& element = header.elements.back();
  PlyProperty property;
  if (w.size() == 5 && w[1] == "list") {
    // PCL takes uchar, ushort, uint and int (as uint) list counts.
    const bool count_type = w[2] == "uchar" || w[2] == "uint8" || w[2] == "ushort" || w[2] == "uint16" ||
                            w[2] == "uint" || w[2] == "uint32" || w[2] == "int" || w[2] == "int32";
    if (!count_type || ply_type_size(w[3]) == 0)
      refuse("property list: unsupported types " + shown(w[2]) + " " + shown(w[3]));
    property = PlyProperty{w[4], ply_type_size(w[2]), true};
  } else {
    expect_words(w, 3, "property <type> <name>' or 'property list <count type> <type> <name>");
    if (ply_type_size(w[1]) == 0) refuse("property: unknown type " + shown(w[1]));
    property = PlyProperty{w[2], ply_type_size(w[1]), false};
  }
  for (const PlyProperty& other : element.properties) {
    if (other.name == property.name) refuse("property " + shown(property.name) + " appears twice");
  }
  if (element.properties.size() == kMaxFields)
    refuse("more than " + std::to_string(kMaxFields) + " properties");
  element.properties.push_back(property);
}

void read_element(const Words& w, PlyHeader& header) {
  expect_words(w, 3, "element <name> <count>");
  for (const PlyElement& other : header.elements) {
    if (other.name == w[1]) refuse("element " + shown(w[1]) + " appears twice");
  }
  if (header.elements.size() == kMaxFields) refuse("more than " + std::to_string(kMaxFields) + " elements");
  header.elements.push_back(PlyElement{w[1], integer(w[2], kMaxCloudPoints, "element " + shown(w[1])), {}});
  if (w[1] == "vertex" && (header.columns == 0 || header.rows == 0)) {
    header.columns = header.elements.back().count;
    header.rows = 1;
  }
}

// PCL reads obj_info num_cols/num_rows (the organized size) and echo_rgb_offset_x/y/z (the viewpoint).
void read_obj_info(const Words& w, PlyHeader& header) {
  if (w.size() < 3) return;
  const std::string what = "obj_info " + std::string(w[1]);
  if (w[1] == "num_cols") header.columns = integer(w[2], kMaxCloudPoints, what);
  if (w[1] == "num_rows") header.rows = integer(w[2], kMaxCloudPoints, what);
  if (w[1] == "echo_rgb_offset_x" || w[1] == "echo_rgb_offset_y" || w[1] == "echo_rgb_offset_z")
    (void)finite_number(w[2], what);
}

void read_format(const Words& w, PlyHeader& header, bool& seen) {
  expect_words(w, 3, "format ascii|binary_little_endian|binary_big_endian 1.0");
  if (seen) refuse("format: appears twice");
  if (!header.elements.empty()) refuse("format: after an element");
  if (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian")
    refuse("format: unknown format " + shown(w[1]));
  if (w[2] != "1.0") refuse("format: version " + shown(w[2]) + " is not 1.0");
  header.ascii = w[1] == "ascii";
  seen = true;
}

PlyHeader parse_ply(std::string_view head) {
  // PCL ends lines at '\n', or at '\r' skipping one more character when the first line ends in "\r".
  const bool crlf = head.substr(0, 5) == "ply\r\n";
  if (!crlf && head.substr(0, 4) != "ply\n") refuse("not a PLY file (first line is not 'ply')");
  const std::string_view terminator = crlf ? "\r\n" : "\n";
  PlyHeader header;
  bool format_seen = false;
  for (std::size_t pos = crlf ? 5 : 4;;) {
    const std::size_t end = head.find(terminator, pos);
    if (end == kNone) refuse_unterminated(head, "not a PLY file (no end_header)");
    const std::string_view line = head.substr(pos, end - pos);
    pos = end + terminator.size();
    if (line.empty() || is_blank(line[0])) refuse("header line " + shown(line) + " is blank or indented");
    if (line.substr(0, 8) == "comment " || line == "comment") continue;
    const Words w = words(line);
    if (w[0] == "format")
      read_format(w, header, format_seen);
    else if (w[0] == "element")
      read_element(w, header);
    else if (w[0] == "property")
      read_property(w, header);
    else if (w[0] == "obj_info")
      read_obj_info(w, header);
    else if (w == Words{"end_header"}) {
      if (!format_seen) refuse("no format line");
      header.data_start = pos;
      return header;
    } else {
      refuse("not a PLY file (unexpected header line " + shown(line) + ")");
    }
  }
}

const PlyElement& vertex_element(const PlyHeader& header) {
  const PlyElement* vertex = nullptr;
  for (const PlyElement& element : header.elements) {
    // PCL loops over the instances of an element without properties without reading a byte (its writer
    // puts an empty "element face 0").
    if (element.properties.empty() && element.count > 0)
      refuse("element " + shown(element.name) + " has instances but no properties");
    // PCL copies range_grid entries by the indices they hold, unchecked for negatives.
    if (element.name == "range_grid") refuse("element range_grid (PCL's organized PLY) is not supported");
    if (element.name == "vertex") vertex = &element;
  }
  if (vertex == nullptr) refuse("has no vertex element");
  bool has_x = false, has_y = false, has_z = false;
  for (const PlyProperty& property : vertex->properties) {
    // PCL sizes the whole cloud by the first vertex's list length.
    if (property.list) refuse("vertex property " + shown(property.name) + " is a list");
    has_x |= property.name == "x";
    has_y |= property.name == "y";
    has_z |= property.name == "z";
  }
  if (!has_x || !has_y || !has_z) refuse("has no x, y, z properties");
  return *vertex;
}

void check_ply_claims(const PlyHeader& header, std::uint64_t file_size) {
  const PlyElement& vertex = vertex_element(header);
  if (header.columns * header.rows != vertex.count) {
    refuse("obj_info num_cols x num_rows (" + std::to_string(header.columns) + " x " +
           std::to_string(header.rows) + ") is not the vertex count " + std::to_string(vertex.count));
  }
  std::uint64_t vertex_bytes = 0;
  for (const PlyProperty& property : vertex.properties) vertex_bytes += property.min_bytes;
  (void)cloud_bytes(vertex.count, vertex_bytes);
  std::uint64_t needed = 0;
  for (const PlyElement& element : header.elements) {
    std::uint64_t row = 0;
    for (const PlyProperty& property : element.properties) row += header.ascii ? 2 : property.min_bytes;
    needed += element.count * row;  // counts and rows are bounded: no overflow
  }
  // ascii: each value is at least one character and a separator (the last one's is optional).
  expect_data(header.ascii ? needed - 1 : needed, file_size - header.data_start, "the elements");
}

}  // namespace

void check_pcd(std::string_view head, std::uint64_t file_size) {
  const PcdHeader header = parse_pcd(head);
  check_data_start(head, header.data_start, file_size);
  check_pcd_claims(header, head, file_size);
}

void check_ply(std::string_view head, std::uint64_t file_size) {
  check_ply_claims(parse_ply(head), file_size);
}

}  // namespace cellmap::cloud_header

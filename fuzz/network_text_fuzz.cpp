// SPDX-License-Identifier: Apache-2.0
// Text from the network, whoever wrote it, on its way to a log, a page or a JSON document: single_line()
// must return valid UTF-8 with no control, line-separator or bidirectional character, within its byte
// bound, and be idempotent; the viewer's JSON writer (status reports, a daemon gone, a version, the whole
// state) must write a document that parses, whatever the cell id, state, reason and sensor names hold.
// The first byte of the input picks the byte bound; the rest is the text.
#include <cstdio>
#include <cstdlib>

#include <nlohmann/json.hpp>

#include "cellmap/common/text.hpp"
#include "cellmap/view/view_state.hpp"
#include "fuzz_support.hpp"

namespace {

using namespace cellmap;

void fail(const char* what, const std::string& text) {
  std::fprintf(stderr, "%s: %zu bytes\n", what, text.size());
  std::abort();
}

// The code point at `i` of valid UTF-8 and its length, or -1 when the bytes there are not one.
long next_code_point(const std::string& s, std::size_t i, std::size_t* length) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char lead = byte(i);
  if (lead < 0x80) return *length = 1, lead;
  const std::size_t n = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC2 ? 2 : 0;
  if (n == 0 || lead > 0xF4 || i + n > s.size()) return -1;
  long code = lead & (0x7F >> n);
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return -1;
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  const long smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < smallest[n] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return -1;
  *length = n;
  return code;
}

bool is_forbidden(long c) {
  return c < 0x20 || (c >= 0x7F && c <= 0x9F) || c == 0x2028 || c == 0x2029 || c == 0x061C || c == 0x200E ||
         c == 0x200F || (c >= 0x202A && c <= 0x202E) || (c >= 0x2066 && c <= 0x2069);
}

void require_clean(const std::string& text, std::size_t max_bytes) {
  if (text.size() > max_bytes) fail("single_line: over its bound", text);
  for (std::size_t i = 0, n = 0; i < text.size(); i += n) {
    const long c = next_code_point(text, i, &n);
    if (c < 0) fail("single_line: not valid UTF-8", text);
    if (is_forbidden(c)) fail("single_line: a control or bidirectional character", text);
  }
  if (single_line(text, max_bytes) != text) fail("single_line: not idempotent", text);
}

void require_json(const std::string& document) {
  if (!nlohmann::json::accept(document)) fail("view: a message that is not JSON", document);
}

void through_the_viewer(const std::string& text) {
  transport::CellStatus status;
  status.cell = text;
  status.state = text;
  status.reason = text;
  status.sensors.push_back({text, text});
  require_json(view::status_json(status));
  view::ViewState state(0, "");
  require_json(state.on_status(status));
  if (!text.empty()) {  // an environment always names its cell
    const Environment env(text, 1, 0, {});
    EnvironmentDelta delta;
    delta.cell = text;
    delta.to_version = 1;
    require_json(state.on_version(env, delta, 0));
  }
  require_json(state.on_daemon_gone(text));
  require_json(state.state());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t max_bytes = data[0] == 0xFF ? std::string::npos : data[0];
  const std::string text = fuzz::text(data + 1, size - 1);
  require_clean(single_line(text, max_bytes), max_bytes);
  through_the_viewer(text);
  return 0;
}

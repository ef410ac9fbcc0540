// SPDX-License-Identifier: Apache-2.0
// hrcsense — the udp_json datagram parser (the robot state source is udp_json_state.cpp).
//
// The parser is hand-written, not nlohmann-json: the format is one flat object of three keys,
// and a small recursive-descent reader over it can (a) stop at the first error with a message
// naming the field and element ("q[3]: expected a number, got a string"), (b) see duplicate keys,
// which nlohmann's DOM silently overwrites, (c) tell an integer token from 1e9 for t_ns, (d) take
// Python's NaN / Infinity tokens in q and qd so that a sender reporting a non-finite joint is
// counted by the history as non-finite rather than as garbage, and (e) allocate nothing on a
// good datagram. It accepts a strict subset of JSON: keys without escapes, nothing nested.
#include "hrcsense/net/udp_json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <system_error>
#include <utility>

namespace hrcsense {
namespace {

std::string size_error(size_t size) {
  return "datagram of " + std::to_string(size) + " bytes: more than " + std::to_string(kUdpJsonMaxBytes);
}

// A cursor over one datagram. Every read either advances past what it read or sets `error`
// (the first error wins) and returns false.
class Reader {
 public:
  Reader(const char* bytes, size_t size) : p_(bytes), end_(bytes + size), begin_(bytes) {}

  bool parse(UdpJsonDatagram& out) {
    skip_ws();
    if (!eat('{')) return fail("expected a JSON object {\"t_ns\": ..., \"q\": [...], \"qd\": [...]}");
    bool seen[4] = {false, false, false, false};
    static const char* const kNames[4] = {"t_ns", "q", "qd", "speed_fraction"};
    skip_ws();
    if (!eat('}')) {
      for (;;) {
        int key = -1;
        if (!read_key(key)) return false;
        if (seen[key]) return fail(std::string("duplicate key '") + kNames[key] + "'");
        seen[key] = true;
        skip_ws();
        if (!eat(':')) return fail_at(std::string(kNames[key]) + ": expected ':'");
        skip_ws();
        const bool read = key == 0   ? read_time(out.t_ns)
                          : key == 3 ? read_fraction(out.speed_fraction)
                                     : read_joints(kNames[key], key == 1 ? out.q_rad : out.qd_rad_s);
        if (!read) return false;
        skip_ws();
        if (eat('}')) break;
        if (!eat(',')) return fail_at(std::string("after ") + kNames[key] + ": expected ',' or '}'");
        skip_ws();
      }
    }
    for (int key = 0; key < 3; ++key) {  // speed_fraction is optional
      if (!seen[key]) return fail(std::string("missing key '") + kNames[key] + "'");
    }
    skip_ws();
    if (p_ != end_) return fail_at("trailing bytes after the object");
    out.ok = !non_finite_;
    out.non_finite = non_finite_;
    if (non_finite_) out.error = non_finite_field_ + ": not a finite number";
    return true;
  }

  std::string error;

 private:
  const char* p_;
  const char* end_;
  const char* begin_;
  bool non_finite_ = false;
  std::string non_finite_field_;

  bool fail(std::string message) {
    error = std::move(message);
    return false;
  }
  bool fail_at(const std::string& message) {
    if (p_ == end_) return fail(message + " at byte " + std::to_string(p_ - begin_) + " (end of datagram)");
    return fail(message + " at byte " + std::to_string(p_ - begin_));
  }
  void skip_ws() {
    while (p_ != end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\n' || *p_ == '\r')) ++p_;
  }
  bool eat(char c) {
    if (p_ == end_ || *p_ != c) return false;
    ++p_;
    return true;
  }
  bool starts_with(const char* word) const {
    const size_t n = std::strlen(word);
    return static_cast<size_t>(end_ - p_) >= n && std::memcmp(p_, word, n) == 0;
  }
  // What kind of JSON value starts here, for "expected X, got Y".
  const char* kind() const {
    if (p_ == end_) return "the end of the datagram";
    switch (*p_) {
      case '"': return "a string";
      case '[': return "an array";
      case '{': return "an object";
      case 't': return starts_with("true") ? "true" : "an invalid token";
      case 'f': return starts_with("false") ? "false" : "an invalid token";
      case 'n': return starts_with("null") ? "null" : "an invalid token";
      default: return (*p_ == '-' || (*p_ >= '0' && *p_ <= '9')) ? "a number" : "an invalid token";
    }
  }

  // A key: t_ns (0), q (1), qd (2) or speed_fraction (3), spelt plainly.
  bool read_key(int& key) {
    const char* const start = p_;
    if (!eat('"')) return fail_at("expected a key (\"t_ns\", \"q\" or \"qd\")");
    const char* const name = p_;
    while (p_ != end_ && *p_ != '"') {
      const auto c = static_cast<unsigned char>(*p_);
      if (c == '\\' || c < 0x20) return fail_at("key: escapes and control characters are not accepted in keys");
      ++p_;
    }
    if (p_ == end_) return fail_at("unterminated key");
    const std::string_view text(name, static_cast<size_t>(p_ - name));
    ++p_;
    if (text == "t_ns") key = 0;
    else if (text == "q") key = 1;
    else if (text == "qd") key = 2;
    else if (text == "speed_fraction") key = 3;
    else {
      const bool printable = text.size() <= 32 && std::all_of(text.begin(), text.end(), [](char c) {
                               return c >= 0x20 && c < 0x7F;
                             });
      const std::string shown = printable ? "'" + std::string(text) + "'" : "at byte " + std::to_string(start - begin_);
      return fail("unknown key " + shown + " (expected t_ns, q, qd, speed_fraction)");
    }
    return true;
  }

  // The digits of a JSON number: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?. Sets `integer`
  // when there is neither fraction nor exponent. Does not move on failure.
  bool scan_number(const char*& number_end, bool& integer) const {
    const char* q = p_;
    if (q != end_ && *q == '-') ++q;
    if (q == end_ || !(*q >= '0' && *q <= '9')) return false;
    if (*q == '0') {
      ++q;
    } else {
      while (q != end_ && *q >= '0' && *q <= '9') ++q;
    }
    integer = true;
    if (q != end_ && *q == '.') {
      ++q;
      if (q == end_ || !(*q >= '0' && *q <= '9')) return false;
      while (q != end_ && *q >= '0' && *q <= '9') ++q;
      integer = false;
    }
    if (q != end_ && (*q == 'e' || *q == 'E')) {
      ++q;
      if (q != end_ && (*q == '+' || *q == '-')) ++q;
      if (q == end_ || !(*q >= '0' && *q <= '9')) return false;
      while (q != end_ && *q >= '0' && *q <= '9') ++q;
      integer = false;
    }
    number_end = q;
    return true;
  }

  bool read_time(int64_t& t_ns) {
    const char* number_end = nullptr;
    bool integer = false;
    if (!scan_number(number_end, integer)) {
      return fail(std::string("t_ns: expected an integer, got ") + kind());
    }
    int64_t value = 0;
    const std::from_chars_result r = std::from_chars(p_, number_end, value);
    if (!integer || r.ec != std::errc() || r.ptr != number_end || value < 0 || value > kUdpJsonMaxTimeNs) {
      return fail("t_ns: expected an integer from 0 to " + std::to_string(kUdpJsonMaxTimeNs) + ", got " +
                  std::string(p_, std::min<size_t>(32, static_cast<size_t>(number_end - p_))));
    }
    t_ns = value;
    p_ = number_end;
    return true;
  }

  // speed_fraction: a plain JSON number from 0 to 1 (a non-finite or larger one says nothing
  // a scale could be computed against: the datagram is malformed).
  bool read_fraction(double& fraction) {
    const char* number_end = nullptr;
    bool integer = false;
    double value = 0.0;
    if (!scan_number(number_end, integer)) return fail(std::string("speed_fraction: expected a number, got ") + kind());
    const std::from_chars_result r = std::from_chars(p_, number_end, value);
    if (r.ec != std::errc() || r.ptr != number_end || !(value >= 0.0 && value <= 1.0)) {
      return fail("speed_fraction: expected a number from 0 to 1, got " +
                  std::string(p_, std::min<size_t>(32, static_cast<size_t>(number_end - p_))));
    }
    fraction = value;
    p_ = number_end;
    return true;
  }

  // One element of q or qd: a JSON number, or Python's NaN, Infinity, -Infinity.
  // `name`[`index`] names it in messages (built only on failure: a good datagram allocates nothing).
  bool read_joint(const char* name, size_t index, double& value) {
    const auto field = [&] { return std::string(name) + "[" + std::to_string(index) + "]"; };
    for (const auto& [word, v] : {std::pair<const char*, double>{"NaN", std::numeric_limits<double>::quiet_NaN()},
                                  {"Infinity", std::numeric_limits<double>::infinity()},
                                  {"-Infinity", -std::numeric_limits<double>::infinity()}}) {
      if (starts_with(word)) {
        p_ += std::strlen(word);
        value = v;
        if (!non_finite_) non_finite_field_ = field();
        non_finite_ = true;
        return true;
      }
    }
    const char* number_end = nullptr;
    bool integer = false;
    if (!scan_number(number_end, integer)) return fail(field() + ": expected a number, got " + kind());
    // from_chars: locale-independent and correctly rounded, unlike strtod.
    const std::from_chars_result r = std::from_chars(p_, number_end, value);
    if (r.ec != std::errc() || r.ptr != number_end) {
      return fail(field() + ": number out of range: " +
                  std::string(p_, std::min<size_t>(32, static_cast<size_t>(number_end - p_))));
    }
    p_ = number_end;
    return true;
  }

  bool read_joints(const char* name, JointAngles& values) {
    const auto field = [&] { return std::string(name); };
    if (!eat('[')) {
      return fail(field() + ": expected an array of " + std::to_string(kJointCount) + " numbers, got " + kind());
    }
    size_t count = 0;
    skip_ws();
    if (!eat(']')) {
      for (;;) {
        double value = 0.0;
        if (!read_joint(name, count, value)) return false;
        if (count < kJointCount) values[count] = value;
        ++count;
        skip_ws();
        if (eat(']')) break;
        if (!eat(',')) return fail_at(field() + ": expected ',' or ']'");
        skip_ws();
      }
    }
    if (count != kJointCount) {
      return fail(field() + ": expected " + std::to_string(kJointCount) + " numbers, got " + std::to_string(count));
    }
    return true;
  }
};

}  // namespace

UdpJsonDatagram parse_udp_json_state(const char* bytes, size_t size) {
  UdpJsonDatagram out;
  if (size == 0) {
    out.error = "empty datagram";
    return out;
  }
  if (size > kUdpJsonMaxBytes) {
    out.error = size_error(size);
    return out;
  }
  Reader reader(bytes, size);
  if (!reader.parse(out)) {
    out = UdpJsonDatagram{};
    out.error = std::move(reader.error);
  }
  return out;
}

}  // namespace hrcsense

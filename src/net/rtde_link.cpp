// SPDX-License-Identifier: Apache-2.0
// hrcsense — `link.rtde.write`: the verdict's speed scale written to a UR controller's RTDE
// inputs (the speed slider, or a double register for a URScript) by a writer thread with its
// own connection; frame() never touches the network (../shared/specs/ur-rtde.md, docs/SAFETY.md).
#include "hrcsense/net/rtde.hpp"
#include "rtde_protocol.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace hrcsense {
namespace {

constexpr int kSliceMs = 20;  // every wait of the writer looks at the stop request this often
constexpr size_t kLinkReceiveChunk = 4096;

const char* mode_name(RtdeLinkParams::Mode mode) {
  return mode == RtdeLinkParams::Mode::speed_slider ? "speed_slider" : "register";
}

std::chrono::nanoseconds seconds(double s) { return std::chrono::nanoseconds(std::llround(s * 1e9)); }

}  // namespace

/// One connection: the socket and the controller's bytes not yet framed.
struct RtdeLinkSink::Connection {
  int fd = -1;
  uint8_t recipe_id = 0;
  std::vector<uint8_t> buffer = std::vector<uint8_t>(2 * kLinkReceiveChunk);
  size_t begin = 0, end = 0;
  std::string error;       // why the connection ended
  bool malformed = false;  // ...because the controller sent something unparseable

  Connection() = default;
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  ~Connection() {
    if (fd >= 0) ::close(fd);
  }

  // Sends all of `bytes` within about 1 s (real time); false with `error` otherwise.
  bool send(const std::vector<uint8_t>& bytes, const std::atomic<bool>& stop) {
    size_t sent = 0;
    for (int tries = 0; sent < bytes.size() && tries < 50 && !stop; ++tries) {
      const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n > 0) {
        sent += static_cast<size_t>(n);
      } else if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        error = std::string("send: ") + std::strerror(errno);
        return false;
      } else {
        pollfd p{fd, POLLOUT, 0};
        ::poll(&p, 1, kSliceMs);
      }
    }
    if (sent < bytes.size() && error.empty()) error = "send: the controller does not take the bytes";
    return sent == bytes.size();
  }

  // Reads what is there (waiting at most `wait_ms`) and takes the next package into `frame`.
  // 1: a package; 0: none yet; -1: the connection ended (error, malformed set).
  int next(rtde::Package& frame, int wait_ms) {
    const int buffered = next_buffered(frame);
    if (buffered != 0) return buffered;
    if (begin > 0) {  // keep room for a read
      std::memmove(buffer.data(), buffer.data() + begin, end - begin);
      end -= begin;
      begin = 0;
    }
    if (buffer.size() - end < kLinkReceiveChunk) buffer.resize(end + 2 * kLinkReceiveChunk);  // a package is < 64 KiB
    pollfd p{fd, POLLIN, 0};
    const int rc = ::poll(&p, 1, wait_ms);
    if (rc <= 0) return 0;
    const ssize_t n = ::recv(fd, buffer.data() + end, buffer.size() - end, MSG_DONTWAIT);
    if (n > 0) {
      end += static_cast<size_t>(n);
      return next_buffered(frame);
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
    if (n < 0) {
      error = std::string("recv: ") + std::strerror(errno);
    } else if (end > begin) {
      error = "connection closed inside a package";
      malformed = true;
    } else {
      error = "connection closed by the controller";
    }
    return -1;
  }

 private:
  // The next package already in the buffer: 1 taken, 0 none complete yet, -1 malformed.
  int next_buffered(rtde::Package& frame) {
    const rtde::PackageSplit split = rtde::split_package(buffer.data() + begin, end - begin);
    if (split.status == rtde::SplitStatus::package) {
      frame = split.package;
      begin += split.consumed;
      return 1;
    }
    if (split.status == rtde::SplitStatus::malformed) {
      error = split.error;
      malformed = true;
      return -1;
    }
    return 0;
  }
};

RtdeLinkSink::RtdeLinkSink(RtdeLinkParams params, const RunClock& clock) : params_(std::move(params)), clock_(clock) {
  if (params_.mode == RtdeLinkParams::Mode::input_register &&
      (params_.register_index < 24 || params_.register_index > 47)) {
    throw std::invalid_argument("link.rtde.register: expected 24..47 (0..23 belong to fieldbus adapters), got " +
                                std::to_string(params_.register_index));
  }
  if (!(params_.min_speed_slider > 0.0 && params_.min_speed_slider <= 1.0)) {
    throw std::invalid_argument("link.rtde.min_speed_slider: expected a fraction in (0, 1]");
  }
  if (!(params_.heartbeat_hz > 0.0) || !std::isfinite(params_.heartbeat_hz)) {
    throw std::invalid_argument("link.heartbeat_hz: expected a positive rate");
  }
  if (params_.mode == RtdeLinkParams::Mode::speed_slider) {
    names_ = "speed_slider_mask,speed_slider_fraction";
    types_ = {"UINT32", "DOUBLE"};
  } else {
    names_ = "input_double_register_" + std::to_string(params_.register_index);
    types_ = {"DOUBLE"};
  }
  period_ns_ = std::max<int64_t>(1, std::llround(1e9 / params_.heartbeat_hz));
  last_frame_ns_ = clock_.now_ns();
  writer_ = std::thread([this] { run(); });
}

RtdeLinkSink::~RtdeLinkSink() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    final_requested_ = true;
    wake_.notify_all();
    // The final stop reaches a connected controller within a write, and one being connected
    // to once it is set up; a writer between attempts (backing off) is not waited for.
    wake_.wait_for(lock, seconds(params_.connect_timeout_s + params_.receive_timeout_s),
                   [this] { return final_written_ || !attempting_; });
  }
  stop_ = true;
  wake_.notify_all();
  writer_.join();
}

double RtdeLinkSink::value_for(VerdictState state, float speed_scale) const {
  const bool slider = params_.mode == RtdeLinkParams::Mode::speed_slider;
  const double floor = slider ? params_.min_speed_slider : 0.0;
  if (state == VerdictState::stop || !std::isfinite(speed_scale)) return floor;
  return std::clamp(static_cast<double>(speed_scale), floor, 1.0);
}

void RtdeLinkSink::frame(const FrameResult& result) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (final_requested_) return;
    pending_ = true;
    pending_stop_ = result.verdict.state == VerdictState::stop;
    pending_value_ = value_for(result.verdict.state, result.verdict.speed_scale);
    have_value_ = true;
    last_frame_ns_ = clock_.now_ns();
  }
  wake_.notify_all();
}

void RtdeLinkSink::summary(const RunSummary&) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    final_requested_ = true;
  }
  wake_.notify_all();
}

RtdeLinkCounters RtdeLinkSink::counters() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

void RtdeLinkSink::problem_locked(const std::string& what) {
  counters_.last_problem = std::string("link.rtde.write ") + mode_name(params_.mode) + ": RTDE " + params_.host +
                           ":" + std::to_string(params_.port) + ": " + what;
}

void RtdeLinkSink::run() {
  double backoff_s = params_.backoff_initial_s;
  while (!stop_) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (final_written_) break;  // nothing is written after the final stop
    }
    if (connect_and_stream()) backoff_s = params_.backoff_initial_s;
    // Back off before the next attempt (a reconnect loop can lock the pendant), in real time,
    // with the socket closed.
    std::unique_lock<std::mutex> lock(mutex_);
    if (final_written_ || stop_) break;
    wake_.wait_for(lock, seconds(backoff_s), [this] { return stop_.load(); });
    backoff_s = std::min(params_.backoff_max_s, 2.0 * backoff_s);
  }
}

bool RtdeLinkSink::connect_and_stream() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    attempting_ = true;
  }
  Connection c;
  std::string error;
  c.fd = rtde::connect_tcp(params_.host, params_.port, params_.connect_timeout_s, stop_, error);
  if (c.fd < 0) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!stop_) counters_.last_problem = std::string("link.rtde.write ") + mode_name(params_.mode) + ": " + error;
    attempting_ = false;
    wake_.notify_all();
    return false;
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.connections;
  }
  const bool streamed = setup(c);
  if (streamed) stream(c);
  const std::lock_guard<std::mutex> lock(mutex_);
  counters_.connected = false;
  attempting_ = false;
  if (!final_written_ && !stop_) {
    counters_.disconnects += streamed ? 1 : 0;
    if (c.malformed) ++counters_.malformed;
    if (!c.error.empty()) problem_locked(c.error);
  }
  wake_.notify_all();  // a destructor waiting for the final stop: there is no connection now
  return streamed;
}

bool RtdeLinkSink::setup(Connection& c) {
  const int timeout_ms = static_cast<int>(std::lround(params_.receive_timeout_s * 1000.0));
  rtde::Package frame;
  // The reply of `type`, skipping text messages and other packages on the way, within the
  // receive timeout (real time).
  const auto reply = [&](rtde::PackageType type) {
    // Bounded in time and in packages (a controller that floods text messages).
    for (int waited = 0, packages = 0; waited <= timeout_ms && packages < 1000 && !stop_;) {
      const int got = c.next(frame, kSliceMs);
      if (got < 0) return false;
      if (got == 0) {
        waited += kSliceMs;
        continue;
      }
      if (frame.type == static_cast<uint8_t>(type)) return true;
      ++packages;
    }
    if (c.error.empty()) c.error = std::string(rtde::package_type_name(static_cast<uint8_t>(type))) + ": no reply";
    return false;
  };
  // A reply that does not parse: counted as malformed, the connection ends.
  const auto bad = [&](const std::string& error) {
    c.error = error;
    c.malformed = true;
    return false;
  };
  const auto refused = [&](const std::string& error) {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.refusals;
    problem_locked(error);
    c.error.clear();  // kept as the problem already; not a disconnect's reason
    return false;
  };
  bool accepted = false;
  std::string error;
  if (!c.send(rtde::encode_request_protocol_version(2), stop_) || !reply(rtde::PackageType::request_protocol_version)) {
    return false;
  }
  if (!rtde::parse_accepted(frame, rtde::PackageType::request_protocol_version, accepted, error)) return bad(error);
  if (!accepted) return refused("REQUEST_PROTOCOL_VERSION: the controller refused protocol version 2");
  rtde::ControllerVersion version;
  if (!c.send(rtde::encode_get_urcontrol_version(), stop_) || !reply(rtde::PackageType::get_urcontrol_version)) {
    return false;
  }
  if (!rtde::parse_controller_version(frame, version, error)) return bad(error);
  rtde::SetupReply setup;
  if (!c.send(rtde::encode_setup_inputs(names_), stop_) || !reply(rtde::PackageType::setup_inputs)) return false;
  if (!rtde::parse_setup_reply(frame, rtde::PackageType::setup_inputs, setup, error)) return bad(error);
  if (!rtde::check_input_setup(setup, names_, types_, error)) return refused(error);
  c.recipe_id = setup.recipe_id;
  if (!c.send(rtde::encode_start(), stop_) || !reply(rtde::PackageType::start)) return false;
  if (!rtde::parse_accepted(frame, rtde::PackageType::start, accepted, error)) return bad(error);
  if (!accepted) return refused("CONTROL_PACKAGE_START: refused by the controller");
  const std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.streaming;
  counters_.connected = true;
  return true;
}

bool RtdeLinkSink::write(Connection& c, double value, bool stop_value) {
  std::vector<rtde::InputValue> values;
  if (params_.mode == RtdeLinkParams::Mode::speed_slider) {
    rtde::InputValue mask;
    mask.type = rtde::InputValue::Type::uint32;
    mask.u32 = 1;  // apply the fraction
    values.push_back(mask);
  }
  rtde::InputValue fraction;
  fraction.f64 = value;
  values.push_back(fraction);
  if (!c.send(rtde::encode_input_data(c.recipe_id, values), stop_)) return false;
  const std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.writes;
  if (stop_value) ++counters_.stop_writes;
  counters_.last_value = value;
  return true;
}

bool RtdeLinkSink::drain(Connection& c) {
  rtde::Package frame;
  for (int k = 0; k < 64; ++k) {  // bounded: a controller that floods the link waits for the next look
    const int got = c.next(frame, 0);
    if (got <= 0) return got == 0;
    if (frame.type != static_cast<uint8_t>(rtde::PackageType::text_message)) continue;
    rtde::TextMessage text;
    std::string error;
    if (!rtde::parse_text_message(frame, text, error)) {
      const std::lock_guard<std::mutex> lock(mutex_);
      ++counters_.malformed;
      problem_locked(error);
    }
  }
  return true;
}

void RtdeLinkSink::stream(Connection& c) {
  const double stop_value = value_for(VerdictState::stop, 0.0F);
  std::unique_lock<std::mutex> lock(mutex_);
  // First the newest verdict when its frame came at most one period ago (after a reconnect
  // too); else, or when none came yet, the stop value, and the next frame's value follows. A
  // value written from the newest frame keeps that frame's heartbeat deadline, so the stop
  // comes one period after the frame, as on a connection that never broke.
  const int64_t start_ns = clock_.now_ns();
  const bool fresh = have_value_ && start_ns - last_frame_ns_ <= period_ns_;
  double value = fresh ? pending_value_ : stop_value;
  bool is_stop = fresh ? pending_stop_ : true;
  pending_ = false;
  int64_t heartbeat_due_ns = fresh ? last_frame_ns_ + period_ns_ : std::max(start_ns, last_frame_ns_) + period_ns_;
  bool due = true;
  while (!stop_) {
    if (final_requested_) {
      lock.unlock();
      const bool written = write(c, stop_value, true);
      lock.lock();
      final_written_ = written;
      wake_.notify_all();
      return;
    }
    if (pending_) {
      value = pending_value_;
      is_stop = pending_stop_;
      pending_ = false;
      due = true;
    }
    heartbeat_due_ns = std::max(heartbeat_due_ns, last_frame_ns_ + period_ns_);
    const int64_t now_ns = clock_.now_ns();
    if (!due && now_ns >= heartbeat_due_ns) {
      // No frame for a period: the stop value, at the heartbeat rate.
      value = stop_value;
      is_stop = true;
      due = true;
      heartbeat_due_ns = now_ns - heartbeat_due_ns >= period_ns_ ? now_ns + period_ns_ : heartbeat_due_ns + period_ns_;
    }
    if (due) {
      due = false;
      if (!is_stop && now_ns - last_frame_ns_ > period_ns_) {
        // A non-stop value is only ever the newest frame's (taken under this lock). Older than
        // a period (the writer was held up: a slow send, a thread not scheduled), the stop
        // value goes out instead, as the heartbeat's would.
        value = stop_value;
        is_stop = true;
        heartbeat_due_ns = now_ns + period_ns_;
      }
      lock.unlock();
      const bool written = write(c, value, is_stop);
      lock.lock();
      if (!written) return;
      continue;
    }
    wake_.wait_for(lock, std::chrono::nanoseconds(std::min(heartbeat_due_ns - now_ns, params_.max_wait_ns)));
    // The controller's side: text messages, anything else skipped by its size; the end of the
    // connection or bytes that cannot be framed end the stream.
    lock.unlock();
    const bool open = drain(c);
    lock.lock();
    if (!open) return;
  }
}

}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// DDS Security on loopback, and across two network namespaces where the test may make them
// (docs/MULTICAMERA.md, "Security"): the test makes a CA, identities,
// a governance and permissions signed by the CA (make_dds_security.sh, openssl), and gives each
// participant nothing but a CYCLONEDDS_URI with a <Security> block, as a cell's processes are
// given theirs. Then a camera with a certificate of the cell's CA reaches a secure reader; a
// participant without security, or with a certificate of another CA, publishing under the same
// camera name, is refused: never matched, never heard; and a camera's certificate lets it publish
// its own measurement topic only. Each participant is a process of its own (dds_security_peer):
// Cyclone reads its configuration once per process. Without the plugins or openssl the tests
// skip. Also here: the fuser's reader counts writers on unconfigured measurement topics, and
// its summary says so.
#include "../support/child_process.hpp"
#include "dds/measurement_endpoints.hpp"
#include "dds_test_util.hpp"
#include "hrcsense/sinks/sinks.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <utility>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense::security_test {

namespace fs = std::filesystem;
using test::ChildProcess;

constexpr const char* kNamespace = "/secure_cell";
// The sessions the writers stamp: which one a reader heard tells who reached it.
constexpr uint32_t kAuthenticatedSession = 1001;
constexpr uint32_t kUnsecuredSession = 2002;
constexpr uint32_t kForeignCaSession = 3003;

/// Why the security tests cannot run here; empty when they can.
std::string missing_prerequisite() {
  if (!test::loopback_configured()) return test::kNoLoopback;
  const std::string plugins = HRCSENSE_DDS_SECURITY_PLUGINS;
  for (const char* plugin : {"libdds_security_auth.so", "libdds_security_ac.so", "libdds_security_crypto.so"}) {
    if (plugins.empty() || !fs::exists(fs::path(plugins) / plugin)) {
      return std::string("Cyclone's DDS Security plugin ") + plugin +
             " is not installed (Debian: libddsc0debian); the security tests skip";
    }
  }
  if (std::string(HRCSENSE_OPENSSL).empty()) return "openssl is not installed (scripts/setup installs it); the security tests skip";
  return {};
}

/// The loopback configuration the tests run with (CYCLONEDDS_URI, file://...), as text.
std::string loopback_config() {
  std::string uri = std::getenv("CYCLONEDDS_URI");
  if (uri.rfind("file://", 0) == 0) uri.erase(0, 7);
  std::ifstream in(uri);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// `base` (a Cyclone configuration) with a <Security> block for `identity`, whose certificate
/// and key are in `dir` with the CA and the signed documents (make_dds_security.sh's layout). The
/// same block as docs/MULTICAMERA.md's example. Empty when `base` has no </Domain>.
std::string secure_config(std::string base, const fs::path& dir, const std::string& identity) {
  const std::string plugins = HRCSENSE_DDS_SECURITY_PLUGINS;
  const auto file = [&](const std::string& name) { return "file:" + (dir / name).string(); };
  const auto library = [&](const std::string& name, const std::string& kind) {
    return "<Library path=\"" + plugins + "/libdds_security_" + name + ".so\" initFunction=\"init_" + kind +
           "\" finalizeFunction=\"finalize_" + kind + "\"/>";
  };
  const std::string security =
      "<Security>"
      "<Authentication>" + library("auth", "authentication") +
      "<IdentityCA>" + file("ca.pem") + "</IdentityCA>"
      "<IdentityCertificate>" + file(identity + ".pem") + "</IdentityCertificate>"
      "<PrivateKey>" + file(identity + ".key") + "</PrivateKey>"
      "</Authentication>"
      "<Cryptographic>" + library("crypto", "crypto") + "</Cryptographic>"
      "<AccessControl>" + library("ac", "access_control") +
      "<PermissionsCA>" + file("ca.pem") + "</PermissionsCA>"
      "<Governance>" + file("governance.p7s") + "</Governance>"
      "<Permissions>" + file("permissions.p7s") + "</Permissions>"
      "</AccessControl>"
      "</Security>";
  const size_t end = base.find("</Domain>");
  if (end == std::string::npos) return {};
  return base.insert(end, security);
}

/// `text` with each `from` replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

/// Where a side's processes run: a command prefix (none, or `ip netns exec NS`), and the
/// configuration files of its participants: `plain` (no security) and one per identity.
struct Side {
  std::vector<std::string> prefix;
  fs::path plain;
  fs::path secure_fuser, secure_front, foreign_front;
};

/// What a peer process said: "ready", "error ...", "session N", "writers N", "unconfigured N".
struct PeerReport {
  bool ready = false;
  std::string error;
  std::set<uint32_t> sessions;
  int32_t writers = 0;
  int64_t unconfigured = 0;
};

/// Reads the lines `peer` has written into `report`, waiting at most `timeout_s` for each (at
/// least a few ms: ChildProcess::read_line reads nothing new without time to wait).
void hear(ChildProcess& peer, PeerReport& report, double timeout_s) {
  std::string line;
  for (int lines = 0; lines < 100 && peer.read_line(line, timeout_s); ++lines) {
    if (line == "ready") report.ready = true;
    if (line.rfind("error ", 0) == 0) report.error = line.substr(6);
    if (line.rfind("session ", 0) == 0) report.sessions.insert(static_cast<uint32_t>(std::stoul(line.substr(8))));
    if (line.rfind("writers ", 0) == 0) report.writers = std::stoi(line.substr(8));
    if (line.rfind("unconfigured ", 0) == 0) report.unconfigured = std::stoll(line.substr(13));
  }
}

/// The path of `ip` (iproute2), empty without it.
std::string ip_command() {
  for (const char* path : {"/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip", "/bin/ip"}) {
    if (fs::exists(path)) return path;
  }
  return {};
}

/// Runs `args` to its end (at most 10 s); whether it exited 0.
bool succeeds(const std::vector<std::string>& args) {
  ChildProcess run(args);
  const int status = run.wait(10.0);
  return status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/// Two network namespaces joined by a veth pair, 192.0.2.1 in `a`, 192.0.2.2 in `b` (a
/// documentation range: the link leads nowhere else), made with iproute2 as root and deleted with
/// this. `why` says why not where they cannot be made (not root, no iproute2, a container that
/// forbids it).
class NamespacePair {
 public:
  NamespacePair() {
    ip_ = ip_command();
    if (::geteuid() != 0) {
      why = "network namespaces need root";
      return;
    }
    if (ip_.empty()) {
      why = "network namespaces need iproute2 (ip)";
      return;
    }
    const std::string tag = std::to_string(::getpid());
    a = "hrcsense_sec_a" + tag;
    b = "hrcsense_sec_b" + tag;
    veth_a = "hrs" + tag + "a";
    veth_b = "hrs" + tag + "b";
    const std::vector<std::vector<std::string>> steps = {
        {ip_, "netns", "add", a},
        {ip_, "netns", "add", b},
        {ip_, "link", "add", veth_a, "type", "veth", "peer", "name", veth_b},
        {ip_, "link", "set", veth_a, "netns", a},
        {ip_, "link", "set", veth_b, "netns", b},
        {ip_, "-n", a, "addr", "add", "192.0.2.1/24", "dev", veth_a},
        {ip_, "-n", b, "addr", "add", "192.0.2.2/24", "dev", veth_b},
        {ip_, "-n", a, "link", "set", veth_a, "up"},
        {ip_, "-n", b, "link", "set", veth_b, "up"},
        {ip_, "-n", a, "link", "set", "lo", "up"},
        {ip_, "-n", b, "link", "set", "lo", "up"},
        {ip_, "netns", "exec", a, "/bin/true"},
    };
    for (const std::vector<std::string>& step : steps) {
      if (!succeeds(step)) {
        why = "network namespaces could not be made here (failed: ip";
        for (size_t i = 1; i < step.size(); ++i) why += " " + step[i];
        why += ")";
        return;
      }
    }
  }
  ~NamespacePair() {
    if (ip_.empty() || a.empty()) return;
    (void)succeeds({ip_, "link", "del", veth_a});  // only if it never moved into its namespace
    (void)succeeds({ip_, "netns", "del", a});      // deletes the veth pair with it
    (void)succeeds({ip_, "netns", "del", b});
  }
  NamespacePair(const NamespacePair&) = delete;
  NamespacePair& operator=(const NamespacePair&) = delete;
  std::vector<std::string> exec_in(const std::string& ns) const { return {ip_, "netns", "exec", ns}; }

  std::string why;
  std::string a, b, veth_a, veth_b;

 private:
  std::string ip_;
};

class DdsSecurity : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string missing = missing_prerequisite();
    if (!missing.empty()) GTEST_SKIP() << missing;
    dir_ = fs::temp_directory_path() / ("hrcsense_dds_security_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ChildProcess make({"/bin/bash", HRCSENSE_DDS_SECURITY_SCRIPT, dir_.string(), "fuser", "front", "left"},
                      (dir_ / "make.log").string());
    const int status = make.wait(60.0);
    ASSERT_TRUE(status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0)
        << "make_dds_security.sh failed: " << (dir_ / "make.log").string();
    loopback_ = side("loopback", loopback_config(), {});
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  /// A side named `name` whose participants take `base` (a Cyclone configuration) and run
  /// behind `prefix`; its configuration files are written into the test's directory.
  Side side(const std::string& name, const std::string& base, std::vector<std::string> prefix) const {
    Side s;
    s.prefix = std::move(prefix);
    const auto write = [&](const std::string& file, const std::string& xml) {
      EXPECT_FALSE(xml.empty()) << "the Cyclone configuration has no </Domain>";
      std::ofstream(dir_ / file) << xml;
      return dir_ / file;
    };
    s.plain = write(name + "_plain.xml", base);
    s.secure_fuser = write(name + "_fuser.xml", secure_config(base, dir_, "fuser"));
    s.secure_front = write(name + "_front.xml", secure_config(base, dir_, "front"));
    s.foreign_front = write(name + "_rogue_front.xml", secure_config(base, dir_ / "rogue", "front"));
    return s;
  }

  /// A peer process (dds_security_peer `args`) on `side` with the configuration `config`.
  std::unique_ptr<ChildProcess> peer(const Side& on, const fs::path& config, const std::vector<std::string>& args) const {
    std::vector<std::string> argv = on.prefix;
    argv.push_back("/usr/bin/env");
    argv.push_back("CYCLONEDDS_URI=file://" + config.string());
    argv.push_back(HRCSENSE_DDS_SECURITY_PEER);
    argv.insert(argv.end(), args.begin(), args.end());
    return std::make_unique<ChildProcess>(argv);
  }

  /// The fuser's side reads "front" twice, secure and plain (the control: it proves the
  /// unauthenticated writers do publish); the camera's side writes "front" three times: with the
  /// cell's certificate, without security, with a certificate and documents of another CA; and an
  /// unsecured "intruder". Only the first reaches the secure reader.
  void expect_only_the_cells_camera_is_heard(const Side& fuser_side, const Side& camera_side) const {
    auto secure_reader = peer(fuser_side, fuser_side.secure_fuser, {"read", domain_, kNamespace, "front", "30"});
    auto plain_reader = peer(fuser_side, fuser_side.plain, {"read", domain_, kNamespace, "front", "30"});
    const auto writer = [&](const fs::path& config, const std::string& camera, uint32_t session) {
      return peer(camera_side, config, {"write", domain_, kNamespace, camera, std::to_string(session), "30"});
    };
    auto camera = writer(camera_side.secure_front, "front", kAuthenticatedSession);
    auto unsecured = writer(camera_side.plain, "front", kUnsecuredSession);
    auto foreign = writer(camera_side.foreign_front, "front", kForeignCaSession);
    auto intruder = writer(camera_side.plain, "intruder", 4004);

    PeerReport secure_heard, plain_heard, camera_said, unsecured_said, foreign_said, intruder_said;
    // Until the secure reader has the camera's measurement and the plain one the unsecured
    // writer's and the intruder (at most 20 s: the handshakes are slow on a loaded machine), then
    // 1 s more, and at least 2 s from the writers' start, in which the refused writers write
    // every 50 ms.
    using Clock = std::chrono::steady_clock;
    const Clock::time_point started = Clock::now();
    Clock::time_point end = started + std::chrono::seconds(20);
    bool all_heard = false;
    while (Clock::now() < end) {
      hear(*secure_reader, secure_heard, 0.02);
      hear(*plain_reader, plain_heard, 0.02);
      hear(*camera, camera_said, 0.005);
      hear(*unsecured, unsecured_said, 0.005);
      hear(*foreign, foreign_said, 0.005);
      hear(*intruder, intruder_said, 0.005);
      if (!all_heard && secure_heard.sessions.count(kAuthenticatedSession) > 0 &&
          plain_heard.sessions.count(kUnsecuredSession) > 0 && plain_heard.unconfigured > 0) {
        all_heard = true;
        end = std::max(Clock::now() + std::chrono::seconds(1), started + std::chrono::seconds(2));
      }
    }
    ASSERT_TRUE(camera_said.ready) << "the secure camera did not start: " << camera_said.error;
    ASSERT_TRUE(foreign_said.ready) << "the foreign-CA writer did not start: " << foreign_said.error;
    ASSERT_TRUE(unsecured_said.ready) << unsecured_said.error;
    ASSERT_TRUE(intruder_said.ready) << intruder_said.error;
    ASSERT_TRUE(secure_reader->running() && plain_reader->running());
    ASSERT_TRUE(all_heard) << "within 20 s: the secure reader heard " << secure_heard.sessions.size()
                           << " sessions, the plain one " << plain_heard.sessions.size() << " and counted "
                           << plain_heard.unconfigured << " unconfigured writers";
    // The secure reader heard the camera only, and matched its writer only.
    EXPECT_EQ(secure_heard.sessions, std::set<uint32_t>{kAuthenticatedSession});
    EXPECT_EQ(secure_heard.writers, 1);
    // The plain reader heard the unsecured writer only: the secure participants do not talk to it.
    EXPECT_EQ(plain_heard.sessions, std::set<uint32_t>{kUnsecuredSession});
    EXPECT_EQ(plain_heard.writers, 1);
    // The intruder: counted by the plain reader, which discovers it; unknown to the secure one.
    EXPECT_EQ(plain_heard.unconfigured, 1);
    EXPECT_EQ(secure_heard.unconfigured, 0);
  }

  /// "left"'s configuration on loopback.
  fs::path left_config() const {
    std::ofstream(dir_ / "loopback_left.xml") << secure_config(loopback_config(), dir_, "left");
    return dir_ / "loopback_left.xml";
  }

  std::string domain_ = std::to_string(test::test_domain());
  fs::path dir_;
  Side loopback_;
};

TEST_F(DdsSecurity, OnlyACameraOfTheCellsCaReachesTheSecureReader) {
  expect_only_the_cells_camera_is_heard(loopback_, loopback_);
}

/// The fuser's host and the camera's host as two network namespaces joined by a veth pair; the
/// test skips before it makes any certificate where they cannot be made.
class DdsSecurityAcrossNamespaces : public DdsSecurity {
 protected:
  void SetUp() override {
    const std::string missing = missing_prerequisite();
    if (!missing.empty()) GTEST_SKIP() << missing;
    hosts_ = std::make_unique<NamespacePair>();
    if (!hosts_->why.empty()) GTEST_SKIP() << hosts_->why;
    DdsSecurity::SetUp();
  }
  std::unique_ptr<NamespacePair> hosts_;
};

TEST_F(DdsSecurityAcrossNamespaces, OnlyACameraOfTheCellsCaReachesTheSecureReader) {
  // The same processes as on loopback, the configuration moved onto the pair's addresses.
  const NamespacePair& hosts = *hosts_;
  const std::string base = loopback_config();
  const auto on = [&](const std::string& veth, const std::string& other_address) {
    return replaced(replaced(base, "name=\"lo\"", "name=\"" + veth + "\""), "127.0.0.1", other_address);
  };
  const Side fuser_host = side("host_a", on(hosts.veth_a, "192.0.2.2"), hosts.exec_in(hosts.a));
  const Side camera_host = side("host_b", on(hosts.veth_b, "192.0.2.1"), hosts.exec_in(hosts.b));
  expect_only_the_cells_camera_is_heard(fuser_host, camera_host);
}

TEST_F(DdsSecurity, ACameraMakesOnlyWhatItsPermissionsAllowAndNothingWithoutItsKey) {
  // "left"'s permissions grant publishing rt/*/measurement/left: its own topic is allowed, the
  // topic of "front" is refused when the writer is made.
  auto own = peer(loopback_, left_config(), {"write", domain_, kNamespace, "left", "1", "0"});
  auto other = peer(loopback_, left_config(), {"write", domain_, kNamespace, "front", "1", "0"});
  // A private key that is not there: the process does not fall back to an unsecured participant;
  // making the writer fails and says so.
  std::string xml = secure_config(loopback_config(), dir_, "front");
  const std::string key = (dir_ / "front.key").string();
  xml.replace(xml.find(key), key.size(), (dir_ / "missing.key").string());
  std::ofstream(dir_ / "broken.xml") << xml;
  auto broken = peer(loopback_, dir_ / "broken.xml", {"write", domain_, kNamespace, "front", "1", "0"});

  PeerReport own_said, other_said, broken_said;
  hear(*own, own_said, 20.0);
  hear(*other, other_said, 20.0);
  hear(*broken, broken_said, 20.0);
  EXPECT_TRUE(own_said.ready) << own_said.error;
  EXPECT_FALSE(other_said.ready);
  EXPECT_NE(other_said.error.find("measurement/front"), std::string::npos) << other_said.error;
  EXPECT_FALSE(broken_said.ready);
  EXPECT_FALSE(broken_said.error.empty());
  for (ChildProcess* refused : {other.get(), broken.get()}) {
    const int status = refused->wait(10.0);
    EXPECT_TRUE(status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 3);
  }
}

TEST(UnconfiguredMeasurementTopics, AWriterOnAnUnconfiguredCameraNameIsCountedOnce) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  ros2::MeasurementReader reader(domain, "/count_cell", {"front"});
  const auto writer = [&](const std::string& ns, const std::string& camera) {
    ros2::MeasurementWriterParams params;
    params.domain_id = domain;
    params.node_namespace = ns;
    params.camera_name = camera;
    return std::make_unique<ros2::MeasurementSink>(params);
  };
  // Counted: "intruder" under the cell's namespace. Not counted: the configured camera, and a
  // camera of another namespace.
  const auto intruder = writer("/count_cell", "intruder");
  const auto front = writer("/count_cell", "front");
  const auto elsewhere = writer("/other_cell", "intruder");
  EXPECT_EQ(reader.unconfigured_publishers(), 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < deadline && (reader.unconfigured_publishers() == 0 || reader.writers(0) == 0)) {
    reader.wait(20'000'000);
    reader.take([](size_t, const CameraMeasurement&, const std::string&) {});
  }
  // Later takes do not count the same writer again.
  for (int i = 0; i < 5; ++i) reader.take([](size_t, const CameraMeasurement&, const std::string&) {});
  EXPECT_EQ(reader.writers(0), 1);
  EXPECT_EQ(reader.unconfigured_publishers(), 1);
  EXPECT_EQ(reader.last_unconfigured_topic(), "/count_cell/measurement/intruder");
}

TEST(UnconfiguredMeasurementTopics, TheFusedSummaryCarriesTheCountAndTheLastTopic) {
  // Beside the per-camera intake, in a fused run's summary only (docs/OUTPUT.md).
  std::ostringstream out;
  JsonLinesSink sink(out);
  RunSummary fused;
  fused.cameras.push_back(RunSummary::CameraIntake{});
  fused.cameras.back().name = "front";
  sink.summary(fused);
  fused.unconfigured_measurement_publishers = 2;
  fused.last_unconfigured_measurement_topic = "/hrcsense/measurement/intruder";
  sink.summary(fused);
  sink.summary(RunSummary{});  // a single camera's run
  std::istringstream lines(out.str());
  std::vector<nlohmann::json> summaries;
  for (std::string line; std::getline(lines, line);) summaries.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(summaries.size(), 3U);
  EXPECT_EQ(summaries[0]["unconfigured_measurement_publishers"], 0);
  EXPECT_TRUE(summaries[0]["last_unconfigured_measurement_topic"].is_null());
  EXPECT_EQ(summaries[1]["unconfigured_measurement_publishers"], 2);
  EXPECT_EQ(summaries[1]["last_unconfigured_measurement_topic"], "/hrcsense/measurement/intruder");
  EXPECT_FALSE(summaries[2].contains("unconfigured_measurement_publishers"));
}

}  // namespace hrcsense::security_test

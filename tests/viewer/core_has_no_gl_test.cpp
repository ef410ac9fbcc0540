// SPDX-License-Identifier: Apache-2.0
// DESIGN: `hrcsense` runs on a headless controller and never links OpenGL; only hrcsense-view
// does. Checked on the built executable's dynamic dependencies (ldd).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

namespace {

std::string ldd(const std::string& path) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(("ldd " + path + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) return out;
  std::array<char, 512> buffer{};
  while (fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get()) != nullptr) out += buffer.data();
  return out;
}

TEST(CoreHasNoGl, TheHrcsenseToolLinksNoOpenGlNorGlfw) {
  const std::string libraries = ldd(HRCSENSE_CLI);
  ASSERT_NE(libraries.find("libc.so"), std::string::npos) << "ldd gave nothing useful:\n" << libraries;
  for (const char* gl : {"libGL", "libOpenGL", "libGLX", "libEGL", "libglfw", "libGLdispatch"}) {
    EXPECT_EQ(libraries.find(gl), std::string::npos) << gl << " in\n" << libraries;
  }
}

}  // namespace

// SPDX-License-Identifier: Apache-2.0
// Tests of intrinsics as JSON: field names and model strings as agreed, exact round trips,
// and errors that name the source and the field.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "hrcsense/camera.hpp"
#include "hrcsense/io/io.hpp"

namespace hrcsense {
namespace {

Intrinsics sample(Distortion model) {
  Intrinsics in;
  in.width = 848;
  in.height = 480;
  in.fx = 418.265F;
  in.fy = 418.5F;
  in.ppx = 424.158F;
  in.ppy = 238.24F;
  in.model = model;
  in.coeffs = {-0.055F, 0.062F, 0.0008F, -0.0005F, -0.019F};
  return in;
}

std::string error_of(const std::string& text) {
  try {
    intrinsics_from_json(text, "cell.json");
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no IoError for " << text;
  return {};
}

const char* kGoodIntrinsics = R"({"width":640,"height":480,"fx":390.4315,"fy":390.4315,"ppx":331.3879,"ppy":242.1873,)"
                    R"("model":"Brown Conrady","coeffs":[0,0,0,0,0]})";

TEST(IntrinsicsJson, WritesTheAgreedFields) {
  const auto json = nlohmann::json::parse(intrinsics_to_json(sample(Distortion::inverse_brown_conrady)));
  EXPECT_EQ(json.at("width"), 848);
  EXPECT_EQ(json.at("height"), 480);
  EXPECT_EQ(json.at("model"), "Inverse Brown Conrady");
  EXPECT_DOUBLE_EQ(json.at("ppy").get<double>(), 238.24);  // written as the short decimal
  ASSERT_TRUE(json.at("coeffs").is_array());
  EXPECT_EQ(json.at("coeffs").size(), 5U);
  EXPECT_DOUBLE_EQ(json.at("coeffs")[4].get<double>(), -0.019);
  EXPECT_NE(intrinsics_to_json(sample(Distortion::none)).find("\"fx\":418.265"), std::string::npos);
}

TEST(IntrinsicsJson, RoundTripIsBitExactForEveryModel) {
  for (const Distortion model :
       {Distortion::none, Distortion::modified_brown_conrady, Distortion::inverse_brown_conrady,
        Distortion::ftheta, Distortion::brown_conrady, Distortion::kannala_brandt4}) {
    Intrinsics in = sample(model);
    in.fx = 1000.0F / 3.0F;  // no short decimal: exercises the float round trip
    const Intrinsics back = intrinsics_from_json(intrinsics_to_json(in), "round trip");
    EXPECT_EQ(back.width, in.width);
    EXPECT_EQ(back.height, in.height);
    EXPECT_EQ(back.fx, in.fx);
    EXPECT_EQ(back.fy, in.fy);
    EXPECT_EQ(back.ppx, in.ppx);
    EXPECT_EQ(back.ppy, in.ppy);
    EXPECT_EQ(back.model, model) << distortion_name(model);
    EXPECT_EQ(back.coeffs, in.coeffs);
  }
}

TEST(IntrinsicsJson, ReadsAHandWrittenFile) {
  const Intrinsics in = intrinsics_from_json(kGoodIntrinsics, "cell.json");
  EXPECT_EQ(in.width, 640);
  EXPECT_EQ(in.height, 480);
  EXPECT_FLOAT_EQ(in.fx, 390.4315F);
  EXPECT_FLOAT_EQ(in.ppy, 242.1873F);
  EXPECT_EQ(in.model, Distortion::brown_conrady);
  EXPECT_TRUE(is_pinhole(in));
}

TEST(IntrinsicsJson, ErrorsNameTheSourceAndTheField) {
  nlohmann::json good = nlohmann::json::parse(kGoodIntrinsics);
  for (const char* name : {"width", "height", "fx", "fy", "ppx", "ppy", "model", "coeffs"}) {
    nlohmann::json missing = good;
    missing.erase(name);
    const std::string message = error_of(missing.dump());
    EXPECT_NE(message.find("cell.json"), std::string::npos) << message;
    EXPECT_NE(message.find(std::string("'") + name + "'"), std::string::npos) << message;
  }
  const auto with = [&](const char* name, const nlohmann::json& value) {
    nlohmann::json edited = good;
    edited[name] = value;
    return error_of(edited.dump());
  };
  EXPECT_NE(with("fx", "390").find("'fx'"), std::string::npos);
  EXPECT_NE(with("fy", 0.0).find("'fy'"), std::string::npos);
  EXPECT_NE(with("width", -640).find("'width'"), std::string::npos);
  EXPECT_NE(with("height", 480.5).find("'height'"), std::string::npos);
  EXPECT_NE(with("model", "Pinhole").find("'model'"), std::string::npos);
  EXPECT_NE(with("model", 4).find("'model'"), std::string::npos);
  EXPECT_NE(with("coeffs", nlohmann::json::array({0, 0, 0, 0})).find("'coeffs'"), std::string::npos);
  EXPECT_NE(with("coeffs", nlohmann::json::array({0, 0, "x", 0, 0})).find("'coeffs[2]'"), std::string::npos);
}

TEST(IntrinsicsJson, NotJsonOrNotAnObject) {
  const std::string broken = error_of("{\"width\": 640,");
  EXPECT_NE(broken.find("cell.json"), std::string::npos) << broken;
  EXPECT_NE(broken.find("invalid JSON"), std::string::npos) << broken;
  const std::string array = error_of("[640, 480]");
  EXPECT_NE(array.find("cell.json"), std::string::npos) << array;
  EXPECT_NE(array.find("object"), std::string::npos) << array;
}

}  // namespace
}  // namespace hrcsense

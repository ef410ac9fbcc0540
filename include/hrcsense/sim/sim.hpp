// SPDX-License-Identifier: Apache-2.0
// hrcsense — a simulated D435 (or, with `sim.sensor: structured_light`, a PrimeSense-class
// structured-light camera): a scene of planes, boxes, spheres and capsules, ray-cast into a
// 16-bit depth image with the sensor's artefacts (docs/SIMULATOR.md), a flat-shaded rgb8 image
// from the colour camera, plus ground truth.
#pragma once

#include "hrcsense/camera.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/source.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense {

/// Geometry of one scene object, in the robot base (world) frame, metres.
struct Shape {
  enum class Type { plane, box, sphere, capsule };
  Type type = Type::plane;
  Eigen::Vector3f point = Eigen::Vector3f::Zero();   ///< plane: a point on it; sphere: centre
  Eigen::Vector3f normal = -Eigen::Vector3f::UnitZ(); ///< plane: unit normal (either side)
  Eigen::Vector3f min = Eigen::Vector3f::Zero();     ///< box: axis-aligned lower corner
  Eigen::Vector3f max = Eigen::Vector3f::Zero();     ///< box: axis-aligned upper corner
  Eigen::Vector3f a = Eigen::Vector3f::Zero();       ///< capsule: segment start
  Eigen::Vector3f b = Eigen::Vector3f::Zero();       ///< capsule: segment end
  float radius_m = 0.0F;                             ///< sphere and capsule

  static Shape plane(const Eigen::Vector3f& point, const Eigen::Vector3f& normal) {
    Shape s;
    s.type = Type::plane;
    s.point = point;
    s.normal = normal;
    return s;
  }
  static Shape box(const Eigen::Vector3f& min, const Eigen::Vector3f& max) {
    Shape s;
    s.type = Type::box;
    s.min = min;
    s.max = max;
    return s;
  }
  static Shape sphere(const Eigen::Vector3f& center, float radius_m) {
    Shape s;
    s.type = Type::sphere;
    s.point = center;
    s.radius_m = radius_m;
    return s;
  }
  static Shape capsule(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float radius_m) {
    Shape s;
    s.type = Type::capsule;
    s.a = a;
    s.b = b;
    s.radius_m = radius_m;
    return s;
  }
};

/// Where a moving object is at a time: its shape is translated by `offset_m`.
struct Waypoint {
  double t_s = 0.0;                                  ///< source time (frame index / fps)
  Eigen::Vector3f offset_m = Eigen::Vector3f::Zero(); ///< translation of the whole object
};

/// Surface properties that cost a D435 its depth (specs/d435-sensor-model.md §4 rules 4–5):
/// pixels of such an object drop out in patches at SimParams' per-material rates.
struct Material {
  bool dark = false;         ///< absorbs the projector's near infrared (black fabric, rubber)
  bool shiny = false;        ///< specular: the pattern is reflected away (metal, glass)
  bool low_texture = false;  ///< featureless and beyond the projector's help
};

/// One scene object. Several shapes may form one object (a person made of capsules).
struct SceneObject {
  std::string name;
  std::vector<Shape> shapes;
  /// Static objects belong to the background (label 0); others are people and objects that
  /// enter the cell and get label = 1 + their index among the non-static objects.
  bool is_static = true;
  int64_t first_frame = 0;        ///< first frame in which the object exists
  int64_t last_frame = -1;        ///< last frame in which it exists; -1: until the end
  std::vector<Waypoint> path;     ///< empty: never moves; else linear interpolation, held at the ends
  Material material;              ///< default: a well-textured matte surface
  /// Flat colour in the colour image, 8-bit RGB; unset: kSimPalette[object index % size].
  std::optional<std::array<uint8_t, 3>> color_rgb;
};

/// Colours of objects that set none, by object index: distinct, so that every object stands out.
inline constexpr std::array<std::array<uint8_t, 3>, 8> kSimPalette{{
    {178, 178, 170}, {120, 144, 160}, {196, 170, 120}, {90, 110, 90},
    {220, 80, 60}, {60, 120, 220}, {230, 190, 40}, {150, 80, 170},
}};

/// The depth camera the simulator imitates (`sim.sensor`, docs/SIMULATOR.md).
enum class SimSensor {
  d435,              ///< Intel RealSense D435: active stereo, the defaults of SimParams
  structured_light,  ///< a PrimeSense-class projector and IR camera (Kinect v1, ASUS Xtion)
};

/// The simulated camera and its D435 effects. Defaults are the D435's and are pinned in
/// docs/SIMULATOR.md. `noise` switches every random effect at once (disparity noise and its
/// quantisation, dropouts, flying pixels, speckle); the geometric ones (left band, occlusion
/// shadows, minimum range) follow from the stereo layout and have their own switches.
struct SimParams {
  /// The camera: its intrinsics (d435: the D435i's; structured_light: fx 570 px at 640x480, scaled
  /// with the width) and, through apply_sim_sensor, the defaults of the effects below.
  SimSensor sensor = SimSensor::d435;
  int width = 848;                   ///< 640x480, 848x480 or 1280x720 (D435 intrinsics)
  int height = 480;
  double fps = 30.0;                 ///< nominal frame rate; timestamps are index / fps
  int64_t frames = 600;              ///< length of the simulated sequence
  uint64_t seed = 1;                 ///< noise seed; same seed, same frames
  bool noise = true;                 ///< false: exact depth (still quantised to 1 mm) where valid
  float disparity_noise_px = kD435SubpixelRmsPx;  ///< σ of the Gaussian noise on disparity, new every frame
  float baseline_mm = kD435BaselineMm;            ///< stereo baseline: right imager at +B along x
  float depth_scale_m = 0.001F;      ///< metres per raw unit (quantisation step)
  float disparity_step_px = 1.0F / 32.0F;  ///< disparity quantisation (SDK: 5 fractional bits); 0: off
  bool left_band = true;             ///< no depth where the right imager does not see (first fx·B/Z columns)
  bool occlusion_shadows = true;     ///< no depth where a nearer surface hides the point from the right imager
  float max_disparity_px = 110.0F;   ///< search range: nearer than fx·B/max_disparity_px, no depth; 0: off
  float min_range_m = 0.0F;          ///< > 0: this minimum range instead of the one from max_disparity_px
  /// > 0: a working range: no depth whose measured value lies beyond this or nearer than the
  /// minimum range (metres); 0: no upper limit (the D435's range fades instead of ending).
  float max_range_m = 0.0F;
  float range_dropout = 0.0F;        ///< share of pixels at max_range_m with no depth, new every frame
  float range_dropout_start_m = 0.0F;  ///< range_dropout grows as ((Z − start) / (max − start))² from here
  float edge_jump_px = 1.5F;         ///< a larger true-disparity step between 4-neighbours is a depth edge
  float edge_dropout = 0.25F;        ///< share of pixels beside a depth edge with no depth (fixed per seed)
  float flying_pixels = 0.15F;       ///< share of the other edge pixels mixed towards the far/near side
  /// > 0: edge pixels are drawn anew every frame instead of fixed per seed, and this share of
  /// those that keep a depth takes the other side's (a pixel flickers between the two depths).
  float edge_flicker = 0.0F;
  float dark_dropout = 0.6F;         ///< share of a Material::dark surface with no depth
  float shiny_dropout = 0.35F;       ///< share of a Material::shiny surface with no depth
  float low_texture_dropout = 0.5F;  ///< share of a Material::low_texture surface with no depth
  int material_cell_px = 4;          ///< material dropouts come in square patches of this side, pixels
  float speckle = 0.002F;            ///< share of pixels dropped at random, new every frame
  float correlated_noise_px = 0.0F;  ///< σ of a smooth disparity error fixed per seed; 0: off
  int correlated_cell_px = 32;       ///< correlation length of that error, pixels (≥ 2)
  bool color = true;                 ///< also render the colour camera (Frame::color)
  int color_width = 0;               ///< colour resolution; 0: the depth resolution
  int color_height = 0;
  /// Depth → colour translation, metres (the colour camera's extrinsics, rotation identity).
  /// Default: the test D435i of specs/d435-sensor-model.md §2.
  Eigen::Vector3f color_translation_m{0.01508F, 0.0000046F, 0.00017F};
  /// The shared scene clock (`sim.epoch`, Config::sim_epoch_ns, set by the app when it builds the
  /// simulator): frame 0's time, CLOCK_REALTIME ns. Set: SimSource plays in scene time, frame i
  /// due at epoch + i / fps, joining at the current frame (docs/SIMULATOR.md, "The shared scene
  /// clock"). Unset: frames 0, 1, ... as fast as asked for, stamped i / fps.
  std::optional<int64_t> epoch_ns;
};

/// The name `sim.sensor` gives `sensor`: "d435" or "structured_light" (the configuration parses
/// it, src/config).
const char* sim_sensor_name(SimSensor sensor);

/// Sets `sensor` and the effects' values that model it in `p` (docs/SIMULATOR.md, "Sensor
/// models"): d435 restores SimParams{}'s, structured_light its own (640x480, baseline 75 mm,
/// 1/8 px disparity steps, a 0.5–4.5 m working range, edge flicker, ...). Leaves the frame rate,
/// length, seed, the `noise` switch and the colour camera alone. The configuration applies it
/// before reading the other sim.* keys, so that keys given explicitly override the preset.
void apply_sim_sensor(SimSensor sensor, SimParams& p);

/// A structured-light camera's depth intrinsics: fx = fy = 570 px at 640x480, scaled with the
/// width, principal point at the image centre, no distortion. For PrimeSense's own modes
/// (640x480, 320x240, 160x120) and the D435's (so that a scene written for the D435 runs with
/// either); nullopt for other sizes.
std::optional<Intrinsics> structured_light_intrinsics(int width, int height);

/// A scene: objects plus the camera's pose in the base frame.
struct Scene {
  std::vector<SceneObject> objects;
};

/// Per-pixel rays of a camera at unit depth (x/z, y/z), recomputed when its intrinsics change.
struct SimRays {
  Intrinsics intrinsics;           ///< what the rays were computed for; width 0: not yet
  std::vector<float> x;            ///< per pixel: x/z of the pixel's ray, camera frame
  std::vector<float> y;            ///< per pixel: y/z of the pixel's ray, camera frame
};

/// Buffers a Simulator reuses between frames so that rendering does not allocate after the
/// first frame. Derived data only: never part of the scene, safe to copy or to leave empty.
struct SimScratch {
  SimRays rays;                    ///< the depth camera's
  SimRays color_rays;              ///< the colour camera's
  std::vector<float> color_z_m;    ///< colour camera z-buffer
  std::vector<uint16_t> color_ids; ///< per colour pixel: 1 + index of the object hit, 0: nothing
  std::vector<Shape> shapes_base;  ///< this frame's existing shapes, moved along their paths
  std::vector<uint16_t> shape_labels;  ///< label of each entry of shapes_base
  std::vector<uint16_t> shape_ids;     ///< 1 + scene object index of each entry of shapes_base
  std::vector<uint16_t> object_ids;    ///< per pixel: 1 + index of the object hit, 0: nothing
  std::vector<uint16_t> label_of_id;   ///< label per object id (index 0: nothing hit)
  std::vector<uint8_t> material_of_id; ///< Material as bits (1 dark, 2 shiny, 4 low texture) per id
  std::vector<std::array<uint8_t, 3>> color_of_id;  ///< RGB per object id (index 0: nothing hit, black)
  std::vector<float> disparity_px;     ///< per pixel: noise-free disparity fx·B/Z, 0: nothing hit
  std::vector<uint8_t> hidden;         ///< per pixel: 1 where the stereo geometry gives no depth
  std::vector<float> normal_draws;     ///< this frame's N(0, 1) draw per pixel
  std::vector<uint8_t> row_steps;      ///< per pixel of a row: a large step to a neighbour
  std::vector<float> correlated_px;    ///< fixed correlated disparity error (empty when off)
  uint64_t correlated_key = 0;         ///< what correlated_px was computed for
  PointCloud points_base;          ///< noise-free non-static pixels, base frame (truth contact)
  PointCloud points_camera;        ///< the same points, camera frame
  RobotModel arm_render;           ///< the moving arm's visual capsules this frame (SimArm)
  RobotModel arm_searched;         ///< its searched capsules this frame, for the truth contact
  std::vector<RobotModel> truth_links;  ///< the truth's capsules split by link (GroundTruth::links)
  RobotModel arm_nearby;           ///< the searched capsules a moment before or after (link speeds)
  std::vector<RobotModel> nearby_links;  ///< arm_nearby split by link
  std::vector<float> label_z_m;    ///< hit_at()'s z-buffer
  int64_t label_index = -1;        ///< the frame hit_at() last cast (object_ids, label_z_m hold it); -1: none
};

/// `robot.trajectory.follow_link` (a test and demo feature): the simulated arm obeys the speed
/// scale hrcsense sends, as an arm whose speed slider the link sets. The trajectory's own time
/// then runs at the scale sent last: from each frame time on, at the scale sent when that frame
/// was rendered (so a decision takes effect at the next frame). The renderer, the `sim` robot
/// state (joints at the trajectory time, velocities times the rate, speed_fraction the rate)
/// and the truth all read this one clock. Thread-safe: the capture thread advances it, the
/// processing thread reads it, the output thread reports what was sent.
class TrajectoryClock {
 public:
  struct Reading {
    double trajectory_s = 0.0;  ///< the time on the trajectory (joints_at's t_s)
    double rate = 1.0;          ///< trajectory seconds per frame-time second from then on, 0..1
  };
  TrajectoryClock();
  /// The reading at frame time `t_ns` (the simulator's timeline: a frame's timestamp_ns). A
  /// time later than all before marks it: the trajectory time up to it at the rate in force,
  /// and from it the scale sent last. An earlier time reads the marks (between marks, at the
  /// earlier one's rate). Integer nanoseconds, so that a frame's own time finds its own mark.
  Reading advance_to(int64_t t_ns);
  /// The same without marking: after the last mark, on at its rate.
  Reading at(int64_t t_ns) const;
  /// The link sent `scale` (0..1; anything else is ignored) for the frame of `frame_timestamp_ns`.
  void sent(int64_t frame_timestamp_ns, float scale);
  /// Waits at most `timeout_s` until a scale was sent for a frame at or after
  /// `frame_timestamp_ns`; false on timeout. SimSource's lockstep for unpaced runs.
  bool wait_sent(int64_t frame_timestamp_ns, double timeout_s) const;
  /// The scale sent last (1 before any).
  double scale() const;
  /// Unpaced runs render each frame after the previous one was decided (set_lockstep(true)), so
  /// the loop's delay is one frame however fast the run; paced runs have real time for it.
  void set_lockstep(bool lockstep) { lockstep_ = lockstep; }
  bool lockstep() const { return lockstep_; }

 private:
  struct Mark {
    int64_t t_ns = 0;           ///< frame time
    double trajectory_s = 0.0;  ///< trajectory time then
    double rate = 1.0;          ///< from then on
  };
  Reading read(int64_t t_ns) const;  ///< with mutex_ held

  mutable std::mutex mutex_;
  mutable std::condition_variable sent_changed_;
  std::vector<Mark> marks_;  ///< in frame time order, the oldest dropped in long runs
  double scale_ = 1.0;
  int64_t sent_for_ns_ = -1;
  bool lockstep_ = false;
};

/// An arm the simulator moves along a trajectory (`robot.trajectory`): rendered at each frame's
/// time t = index / fps from joints_at(trajectory, t), with the label kRobotLabel (with a
/// `clock`, at the clock's trajectory time for t instead).
struct SimArm {
  RobotParams robot;           ///< the arm (required), padding and base frame, as the pipeline's
  RobotTrajectory trajectory;  ///< the motion, on the simulator's timeline (index / fps)
  /// Flat colour in the colour image; unset: kSimPalette[scene object count % size].
  std::optional<std::array<uint8_t, 3>> color_rgb;
  /// follow_link: the trajectory time the arm is at (shared with the `sim` robot state); null:
  /// the frame time itself (open loop, full programmed speed).
  std::shared_ptr<TrajectoryClock> clock;
};

/// A knock (`sim.camera_knock_frame`, `sim.camera_knock_T_base_camera`): the camera is moved
/// between two frames, as a bump or a loose mount moves it, and stays there. For tests and
/// checks of what hrcsense does when the pose it was told goes stale (docs/SIMULATOR.md).
struct SimCameraKnock {
  int64_t frame = -1;                     ///< first frame rendered from the knocked pose; < 0: no knock
  Pose T_base_camera = Pose::Identity();  ///< the true pose from `frame` on, base ← camera
};

/// Renders frames of a scene. Deterministic: frame i depends only on (params, scene, i), except
/// for an arm that follows the link (SimArm::clock), which depends on the scales sent.
struct Simulator {
  SimParams params;
  Scene scene;
  /// The camera's true pose, base ← camera, which the frames are rendered from and the truth is
  /// measured with. hrcsense is told its own pose (camera.T_base_camera); the two differ only
  /// when `sim.camera_T_base_camera` says so (docs/SIMULATOR.md, "A camera pose hrcsense is not
  /// told").
  Pose T_base_camera = Pose::Identity();
  /// Moves the true pose from a frame on; default: never.
  SimCameraKnock camera_knock;
  RobotModel robot;  ///< for the ground-truth contact (without `arm`; with it, the arm's searched capsules)
  /// A moving arm; unset: no moving arm (an arm at a fixed pose is a static scene object).
  /// With it, GroundTruth::contact and analytic_contact measure against the arm's searched
  /// capsules (robot_model_at of arm->robot) at the frame's exact time, and the arm's pixels
  /// are neither static nor part of the contact.
  std::optional<SimArm> arm;
  /// Reused buffers; because render() writes them, one Simulator must not render from two
  /// threads at once (copy it instead).
  mutable SimScratch scratch;

  /// The depth intrinsics used: the D435i's for the configured resolution, or
  /// structured_light_intrinsics with SimSensor::structured_light.
  /// Throws std::invalid_argument for a resolution the sensor does not offer.
  Intrinsics intrinsics() const;
  /// The colour intrinsics used (d435_color_intrinsics of the colour resolution).
  /// Throws std::invalid_argument for a resolution it does not know.
  Intrinsics color_intrinsics() const;
  /// Depth → colour extrinsics (SDK layout): identity rotation, params.color_translation_m.
  Extrinsics depth_to_color() const;
  /// Renders frame `index` into `out` (depth, intrinsics, timestamp, baseline, ground truth,
  /// and with params.color the colour image, its intrinsics and the depth → colour extrinsics).
  /// Reuses out's buffers, so rendering into the same Frame does not allocate.
  void render(int64_t index, Frame& out) const;
  /// What the ray of source pixel `pixel` (v * width + u) of frame `index` meets: its truth
  /// label and the noise-free depth Z (m, 0 where nothing is hit), as render() gives them but
  /// without rendering the rest: the same ray cast, so the same label. Casts the whole frame
  /// once per index (scratch keeps it), so asking for several pixels of a frame is cheap.
  /// {kStaticLabel, 0} for a pixel outside the image.
  struct Hit {
    uint16_t label = kStaticLabel;
    float z_m = 0.0F;
  };
  Hit hit_at(int64_t index, int pixel) const;
  /// The true pose frame `index` is rendered from: camera_knock's from its frame on, else
  /// T_base_camera.
  const Pose& T_base_camera_at(int64_t index) const {
    return camera_knock.frame >= 0 && index >= camera_knock.frame ? camera_knock.T_base_camera : T_base_camera;
  }
  uint16_t label_at(int64_t index, int pixel) const { return hit_at(index, pixel).label; }
  /// A label's name: "static", "robot" (kRobotLabel), or the name of the non-static scene
  /// object with that label; "" for a label no object has.
  const std::string& label_name(uint16_t label) const;
  /// The moving arm's trajectory time and rate at frame `index` (index / fps and 1 without a
  /// clock); requires `arm`.
  TrajectoryClock::Reading arm_time(int64_t index) const;
  /// The moving arm's joints at frame `index` (joints_at at arm_time, velocities times its
  /// rate); requires `arm`.
  TrajectorySample arm_joints(int64_t index) const;
};

/// `robot.state.source: sim`: the joints of the simulator's trajectory, on the *simulator's
/// timeline*: state_at(t) answers for t = a frame's timestamp_ns (index / fps in ns), not for a
/// time on the host clock. (The run loop is to pass the frame's host time, which for unpaced
/// sim runs is that timestamp.) Origin `sim`.
///
/// Without latency and jitter the state is exact: joints_at(trajectory, t), stamped t, with
/// speed_fraction 1 (the arm runs at its programmed speed whatever is sent). With a clock
/// (follow_link): joints_at the clock's trajectory time for t, velocities times its rate, and
/// speed_fraction the rate, as a controller reports its slider. With
/// them, samples are taken every `period_s` of the timeline (sample k holds k · period_s and is
/// stamped with that true time, as a controller clock mapped to the host would stamp it) and
/// each becomes known `latency_s` + a jitter later, the jitter uniform in [0, jitter_s) from
/// `seed` and k (deterministic), in order (a sample is never known before the one before it).
/// state_at(t) reads a RobotStateHistory of the samples known by t: the newest is about
/// latency_s old, so the state lags the truth by the latency less the history's one-period
/// extrapolation, and is stale (invalid) past history.max_age_s. An earlier t than the
/// previous call starts afresh (a new run).
class SimRobotState final : public RobotStateSource {
 public:
  struct Params {
    double latency_s = 0.0;    ///< `robot.state.sim_latency_s`: how late each sample is known
    double jitter_s = 0.0;     ///< `robot.state.sim_jitter_s`: extra delay, uniform in [0, jitter_s)
    double period_s = 0.002;   ///< sample period with latency or jitter (500 Hz, an e-Series' rate)
    uint64_t seed = 1;         ///< jitter seed (source.seed)
    RobotStateHistoryParams history;  ///< `robot.state.max_age_s`
    /// follow_link: the simulator's clock (the same object its SimArm has); null: open loop.
    std::shared_ptr<TrajectoryClock> clock;
    /// The shared scene clock (SimParams::epoch_ns): set, state_at is asked at host times (the
    /// steady clock, as SimSource stamps Frame::host_time_ns) and answers for the scene time
    /// they map to (realtime − epoch), stamped back on the steady clock. Unset: the timeline.
    std::optional<int64_t> epoch_ns;
  };
  SimRobotState(RobotTrajectory trajectory, Params params);
  RobotStateOrigin origin() const override { return RobotStateOrigin::sim; }
  /// The state at `time_ns` on the simulator's timeline (a frame's timestamp_ns).
  bool state_at(int64_t time_ns, RobotState& out) override;
  RobotStateStats stats() const override;

 private:
  /// When sample k would become known before the in-order rule, nanoseconds.
  int64_t raw_known_ns(int64_t k) const;
  /// state_at on the simulator's timeline (the scene time with an epoch).
  bool state_on_timeline(int64_t time_ns, RobotState& out);

  RobotTrajectory trajectory_;
  Params params_;
  int64_t period_ns_ = 2'000'000;
  RobotStateHistory history_;
  int64_t next_sample_ = 0;      ///< the first sample not yet added to history_
  int64_t last_known_ns_ = 0;    ///< when the sample before next_sample_ became known
  int64_t last_time_ns_ = 0;     ///< the previous state_at time
  mutable std::mutex mutex_;     ///< stats() may be read while the run calls state_at()
};

/// A D435i colour camera's intrinsics (Inverse Brown-Conrady, zero coefficients, as the
/// camera reports) for a colour resolution: the calibrated 1280x720 and 640x480 rows of
/// specs/d435-sensor-model.md §2, other 16:9 modes (1920x1080, 960x540, 848x480, 640x360,
/// 480x270, 424x240) scaled from 1280x720 by height and cropped about the centre as the
/// sensor does, 320x240 halved from 640x480. nullopt for other sizes.
std::optional<Intrinsics> d435_color_intrinsics(int width, int height);

/// Fill rate as the Depth Quality Tool defines it: valid pixels / pixels in the image, over
/// frames first .. first+count-1 of the simulator. count ≥ 1.
double sim_fill_rate(const Simulator& sim, int64_t first, int64_t count);


/// The simulator as a source, ending after params.frames frames (frame index >= frames).
/// Without params.epoch_ns: frames 0, 1, ... each when asked for, stamped index / fps. With it
/// (the shared scene clock, docs/SIMULATOR.md): live, paced by itself on CLOCK_REALTIME: frame i
/// is due at epoch + i / fps; the first frame is the next one due when next() is first called
/// (a camera started late joins the scene where it is); a frame already late by more than one
/// period is skipped for the newest one due, never delivered in a burst; Frame::index is the
/// scene frame, timestamp_ns its due time (realtime ns) and host_time_ns that instant on the
/// steady clock.
class SimSource : public Source {
 public:
  explicit SimSource(Simulator simulator) : sim_(std::move(simulator)) {}
  SourceInfo info() const override;
  /// With an epoch: waits until the frame is due, but at most kSceneWaitNs; a frame due later
  /// (an epoch in the future) gives `idle`, so that a stop request ends the wait.
  Status next(Frame& out) override;
  /// follow_link in lockstep: frames rendered without the previous frame's scale (the wait ran out).
  int64_t lockstep_timeouts() const { return lockstep_timeouts_; }
  /// Scene frames skipped because they were late by more than a period (with an epoch).
  int64_t frames_dropped_camera() const override { return scene_frames_skipped_; }

  /// The longest wait in one next() call with an epoch, ns.
  static constexpr int64_t kSceneWaitNs = 200'000'000;

 private:
  /// next() with an epoch: the scene frame due now (the index to render), or a status.
  Status next_scene_frame(Frame& out);

  Simulator sim_;
  int64_t next_index_ = 0;
  int64_t lockstep_timeouts_ = 0;
  bool scene_joined_ = false;       ///< with an epoch: the first frame's index was chosen
  int64_t scene_frames_skipped_ = 0;
};

}  // namespace hrcsense

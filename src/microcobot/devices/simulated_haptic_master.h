#pragma once
/// @file
/// The dual-stage haptic interface held by a (simulated) operator: the digital twin behind
/// the HapticMaster interface.
///
/// The operator's hand is a position source (the scripted operator moves it) coupled to the
/// handle through the finger. Along y (the Haptuator's axis, Fig. 3.9) the rendered force goes
/// through the crossover + compensation pipeline (eq. 3.5-3.8) into the 4-mass plant of
/// eq. 3.4, whose finger spring is anchored at the hand: the handle sits at hand + y_h. Along
/// x the Pantograph alone renders and the handle sits at hand + F_x / k_f (the finger's
/// compliance; the hand moves slowly next to the plant's dynamics). The handle stays inside the
/// Pantograph's workspace (the five-bar stops at its limits). A hardware driver of this device
/// would run the same RenderPipeline and send J^T f to the motors (docs/hardware.md).

#include "microcobot/devices/device.h"
#include "microcobot/haptics/dual_stage_plant.h"
#include "microcobot/haptics/pantograph.h"
#include "microcobot/haptics/render_pipeline.h"

namespace mc::devices {

/// What the operator does with the handle (set by the scenario's operator).
struct OperatorHand {
  Vec2 hand_m;           ///< hand position relative to the workspace centre
  bool deadman = false;  ///< enable switch held
  bool clutch = false;   ///< indexing button pressed
  double jog_m_s = 0.0;  ///< thumb wheel
};

class SimulatedHapticMaster final : public HapticMaster {
 public:
  /// Designs the pipeline and discretises the plant at the loop period `dt_s` (allocates).
  SimulatedHapticMaster(std::string name, const haptics::DualStagePlantParams& plant,
                        const haptics::RenderPipelineParams& pipeline,
                        const haptics::PantographParams& pantograph, double dt_s);

  Vec2 handle_position_m() const override { return handle_m_; }
  bool enabled() const override { return hand_.deadman; }
  bool clutch() const override { return hand_.clutch; }
  double jog_m_s() const override { return hand_.jog_m_s; }
  std::uint64_t reading_count() const override { return readings_; }
  void command_force_N(Vec2 force) noexcept override;
  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override;

  /// The scripted operator's hand. Real-time safe.
  void set_operator(const OperatorHand& hand) noexcept { hand_ = hand; }
  const OperatorHand& operator_hand() const { return hand_; }
  /// Fault injection: the readings stop (a stalled bus) while true.
  void freeze_readings(bool frozen) noexcept { frozen_ = frozen; }
  /// The Pantograph's force after the limits: x direct, y the crossover's low band [N].
  Vec2 pantograph_force_N() const { return rendered_; }
  const haptics::RenderOutput& channels() const { return channels_; }
  double haptuator_travel_m() const { return haptics::DualStagePlant::magnet_travel(state_); }

 protected:
  void on_configure() override;

 private:
  haptics::DualStagePlant plant_;
  haptics::RenderPipeline pipeline_;
  haptics::Pantograph pantograph_;
  Eigen::Vector2d centre_;
  haptics::DualStagePlantState state_;
  OperatorHand hand_;
  Vec2 force_cmd_;
  Vec2 rendered_;
  haptics::RenderOutput channels_;
  Vec2 handle_m_;
  std::uint64_t readings_ = 0;
  bool frozen_ = false;
};

}  // namespace mc::devices

#pragma once
/// @file
/// Letting go of a part against adhesion: which of a finger and the seat keeps
/// a part when the fingers open, and the release strategies that tip the balance towards the seat
/// (R. S. Fearing, "Survey of sticking effects for micro parts handling", IROS 1995; S. Haliyo,
/// S. Régnier, Y. Rollot, "Manipulation of micro-objects using adhesion forces and dynamical
/// effects", ICRA 2002). The world is quasi-static (pick_place_world.h): each strategy is a
/// comparison of the forces (or moments) that hold the part, F_s the seat's pull-off, F_f a
/// finger's, W the part's weight, m its mass:
///
///   open    the fingers part: the seat keeps the part when  F_s > 2 F_f              (peel, normal)
///   shake   the opened fingers vibrate along their closing axis at amplitude A and frequency f,
///           so the part must follow an acceleration A (2 pi f)^2 that only adhesion provides:
///           the seat keeps it when  F_s + m A (2 pi f)^2 > 2 F_f   (inertial release, Haliyo et
///           al.); in the air it drops when  W + m A (2 pi f)^2 > 2 F_f
///   roll    the opened fingers turn about the vertical (the rotary axis) with the part on its
///           seat: the finger's flat contact, w wide, peels onto its edge (its pull-off falls to
///           edge_fraction F_f) when the seat holds the part's turn, i.e. when the seat's friction
///           moment beats the moment the contact resists before peeling:
///               mu_s (F_s + W) r_s > F_f w / 2,   r_s = 0.3826 a
///           (r_s: the mean distance of a square of side a from its centre, the friction radius of
///           a uniformly pressed square); a part in a bore is held by its walls. Then
///           F_s > 2 edge_fraction F_f keeps it. A seat too slippery for the moment lets the part
///           turn with the fingers, still stuck.
///
/// margin() is the ratio of what keeps the part on its seat to what keeps it on the fingers:
/// above 1 the strategy releases it. The cell chooses a part's strategy from the margins it is
/// told (the part's and the seat's adhesion, assembly_batch.h); the world decides with the same
/// functions, so the prediction and the simulation cannot drift apart.

#include <string_view>

namespace mc::microworld {

struct PickPlaceParams;

enum class ReleaseStrategy { kOpen, kShake, kRoll };

std::string_view name(ReleaseStrategy r) noexcept;
/// "open", "shake" or "roll"; false for anything else.
bool parse_release(std::string_view text, ReleaseStrategy& out) noexcept;

/// The inertial force on the part while the fingers shake, m A (2 pi f)^2 [N].
double shake_force_N(const PickPlaceParams& p) noexcept;
/// The seat's friction moment on a part resting on it, mu_s (F_s + W) r_s [N m].
double seat_moment_Nm(const PickPlaceParams& p) noexcept;
/// The moment a finger's flat contact resists before it peels, F_f w / 2 [N m].
double finger_peel_moment_Nm(const PickPlaceParams& p) noexcept;
/// What keeps the part on its seat over what keeps it on the fingers for `r` (above 1: released).
/// `in_bore`: the part is down in a bore, whose walls hold its turn.
double release_margin(const PickPlaceParams& p, ReleaseStrategy r, bool in_bore) noexcept;
/// The seat keeps a part the opened fingers touch it with: `shaking` the fingers now, their
/// contact `rolled` onto its edge.
bool seat_keeps(const PickPlaceParams& p, bool shaking, bool rolled) noexcept;
/// A part stuck to an opened finger in the air drops off (its weight and the shake beat it).
bool drops_off(const PickPlaceParams& p, bool shaking, bool rolled) noexcept;

}  // namespace mc::microworld

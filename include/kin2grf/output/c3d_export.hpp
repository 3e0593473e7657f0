// kin2grf outputs: the trial as a C3D with the estimated ground reactions as force platforms, for
// the tools gait labs compute their kinetics with from C3D files (Vicon Nexus, Visual3D, Mokka,
// ezc3d, BTK): they then run their own inverse dynamics on the estimate as on measured plates.
//
// What the file holds:
//  - every marker of the trial as read (mm, the file's own frame numbers; the labels as kin2grf
//    reads them, a Vicon subject prefix removed), a missing sample written with residual -1;
//  - two force platforms of TYPE 2 (force and moment channels at the sensor origin, N and N mm),
//    platform 1 the right foot's estimate, platform 2 the left foot's, sampled at the marker rate:
//    zero outside contact and outside the processed window; the free moment is zero (not
//    estimated). Each platform is a rectangle on the calibrated floor, its x along the feet's path
//    (the progression, turned by the slope of the feet's COPs across it where each foot's span
//    more than kPathSpanM: a walk at an angle to the pelvis's travel) and its y to the walker's
//    right, covering every place its foot's COP takes in
//    the trial and kLoadedFootMarginM beyond them along the progression and on the foot's outer
//    side (the whole foot stands on it while it is loaded). On the inner side the two platforms
//    meet on the line midway between the feet's mean COP paths, so that the other foot never
//    stands on a foot's platform and a tool that assigns each platform to the one foot over it
//    can; where a foot's COPs cross that line (a runner's crossover) or the walker turns (the
//    rectangles then in the lab's x and y), they overlap, and the messages say to assign them
//    by hand. C3D's axes (x = c1 - c2, y = c1 - c4, z = x cross y pointing down) and the sensor
//    origin at the surface centre (ORIGIN 0 0 0: no reader's sign convention for ORIGIN comes
//    into play);
//  - the file's own events, and where it has no "Foot Strike" or "Foot Off" event, the estimate's
//    (gait_events), so that a tool can cut cycles; at most kMaxC3dEvents, the first in time;
//  - the body mass the estimate used (PROCESSING:Bodymass) and the height where the file has one.
// Not carried: the file's own analog channels (its measured plates, EMG), which would add
// measured forces to the estimated ones in an inverse dynamics; the input file is not changed.
//
// Frame: the trial's lab frame when its up axis is +Z (C3D's convention, which ezc3d's platform
// module assumes); otherwise every position, corner and force is rotated by the one rotation that
// takes the trial's up direction to +Z (a TRC in OpenSim's Y-up frame: X stays, Y -> Z, Z -> -Y).
//
// Written with io/c3d.hpp's writer (Intel, float). Tested against ezc3d's reading rules for TYPE 2
// platforms (its ForcePlatforms module: axes from the corners, the COP from the channels), not
// against kin2grf's own reader.
#pragma once

#include <string>
#include <vector>

#include "kin2grf/pipeline.hpp"
#include "kin2grf/trial.hpp"

namespace kin2grf {

/// How far each virtual platform reaches beyond its foot's COPs, m: about half a foot's length,
/// so that the foot around a COP at its heel or its toe is on the platform too.
inline constexpr double kLoadedFootMarginM = 0.15;
/// Each foot's COPs must span more than this along the progression (m) before the direction of
/// their path is taken from them: more than one footprint (within one stance a COP moves about a
/// foot's length, 0.25 m), so a path of two steps or more, not a landing in place.
inline constexpr double kPathSpanM = 0.5;
/// C3D's EVENT group holds this many events (a parameter's dimension is a byte); a longer trial's
/// first ones are written, and the messages say so.
inline constexpr std::size_t kMaxC3dEvents = 255;

struct C3dExport {
  Trial trial;                        ///< markers, platforms, events, mass: what write_c3d writes
  int first_frame = 1;                ///< its first frame number: the trial's, where it fits 1-65535
  std::vector<std::string> messages;  ///< what was done to the frame or the events, for the user
};

/// The trial with the estimate's ground reactions as two TYPE 2 platforms (right, left), in a
/// Z-up lab frame. `trial` is the one the estimate was made from (its markers and events).
C3dExport c3d_export(const Trial& trial, const EstimateResult& estimate);

/// c3d_export written to `path` (Intel, float data, from its first_frame). Returns its messages.
std::vector<std::string> write_c3d_export(const std::string& path, const Trial& trial, const EstimateResult& estimate);

}  // namespace kin2grf

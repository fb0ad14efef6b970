// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the viewer sends its page over the WebSocket at /ws, and what the page may send back. The page
// (viewer/web/viewer.js) decodes exactly this; a change here is a change there.
//
// 1. On connect, and again whenever the world behind the viewer changes (a restarted world, another scene), one text
//    message, the scene:
//      {"type": "scene", "mode": "live" | "replay", "source": "<shm name or trial folder>",
//       "coupling": "impulse" | "position" | "local", "world_rate_hz": 20,
//       "floor": {"present": true, "height_m": 0.0},
//       "bodies": [{"name": "cube", "shape": "box" | "sphere" | ... (common/shape/shape.h to_string), "dynamic": true,
//                   "size_m": [x, y, z], "radius_m": r, "length_m": l}, ...],   (common/shape/shape_descriptor.h)
//       a mesh body also has "mesh_hash": "<16 hex digits>" and "mesh": either
//         {"drawn": "triangles", "vertices_m": [x0, y0, z0, x1, ...], "triangles": [a0, b0, c0, a1, ...]}
//       (body frame, m, to the micrometre; vertex indices, counter-clockwise seen from outside), when the viewer read
//       its file (--meshes-from, or a replay's scene); a mesh of more than kMaxViewMeshTriangles is sent coarsened
//       to at most that many (viewer/mesh_coarsening.h), with "coarsened_from": its own count and "cell_m", or
//         {"drawn": "bound", "why": "..."}: the page draws a ball of radius_m about its centre instead.
//       "replay": {"start_s": t0, "end_s": t1, "frame_count": n},          (replay only)
//       "tool": {"shape": ..., "size_m": ..., "radius_m": ..., "length_m": ...,   (a tool in the hand: a replay's, or
//                                                  live the tool of the scene --meshes-from names; a mesh tool
//                                                  also has "mesh", as a body's)
//                "placement": {"position_m": [x, y, z], "orientation_wxyz": [w, x, y, z]}}}   (shape → grip frame)
//    Body k of every frame below is bodies[k]. A shape's axis of symmetry is its body z.
//
// 2. Each world frame, one binary message: little-endian float64 values (a Float64Array on the page):
//      header, kFrameHeaderValues values:
//        [0] kind = 1 (a frame)       [1] frame index i        [2] world time at the end of step i, s
//        [3] world period, s          [4] body count B         [5] endpoint count E
//        [6] haptic lateness p99, s (NaN: unknown, e.g. lockstep or replay)
//        [7] haptic faults            [8] world skipped periods  [9] haptic skipped periods
//        [10] playing (replay: 1 or 0; live: 1)                  [11] replay speed (live: 1)
//        [12] dent: 1 when a dent follows the endpoints, else 0
//        [13] tool: 1 when the tool's poses follow (after the dent), else 0        [14..15] reserved, 0
//      then B bodies, kBodyValues each: position x, y, z (m), orientation w, x, y, z (unit quaternion, body → world)
//      then E endpoints, each kEndpointValues followed by 6·P plane values:
//        endpoint id, finger valid (1/0), finger x, y, z (m), proxy x, y, z (m), force on the finger x, y, z (N),
//        plane count P; then per plane: point x, y, z (m), outward unit normal x, y, z
//      then, if [12] is 1, the dent of a deformable box's top face (common/contract/world_view.h ViewDent),
//      kDentValues values and C·R depths: body k, version (changes with the dent), columns C, rows R, x0, y0, dx, dy
//      (m, the box's body frame: point (c, r) at (x0 + c·dx, y0 + r·dy) on the top face), then the depths below the
//      face (m), row-major (r·C + c)
//      then, if [13] is 1, the tool, kToolValues values (live: the first endpoint whose reports are a tool's,
//      HapticReport::oriented; none: valid 0): valid (1/0: a grip pose this frame), the grip's pose
//      (x, y, z, qw, qx, qy, qz; grip → world), the proxy's pose (the tool as rendered, held out of the objects), the
//      force on the grip x, y, z (N), the torque on the grip about its centre x, y, z (N·m)
//    World frame right-handed, z up, SI units.
//
// 3. Page → viewer (replay only; ignored live), text messages of one JSON object:
//      {"play": true | false}   {"speed": 0.1 .. 10}   {"seek": seconds of trial time}
//    Anything else, or a message over kMaxClientMessageBytes, closes that connection; the viewer carries on.
//
// 4. Touch (viewer --touch; viewer/touch_control.h, viewer/web/touch.js). On the page's touch socket at /ws/touch
//    (no scene, no frames; the page's worker, viewer/web/touch_worker.js, holds it) or on /ws. Page → viewer:
//      {"touch": "take", "token": "<the run's token, from the page's address ?touch=TOKEN>"}
//      {"touch": "target", "target_m": [x, y, z]}     the holder's target, at least every 10 ms (its heartbeat)
//      {"touch": "release"}
//    Viewer → page, a text message answering a take or a release, or a target from a page that does not hold:
//      {"type": "touch", "state": "holding" | "watching" | "released" | "refused" | "unavailable",
//       "reason": "...",                                     (why, when not holding)
//       "hand": {"finger_m": [x, y, z], "workspace_min_m": [..], "workspace_max_m": [..], "max_force_N": f}}
//    A malformed touch message closes the connection as in §3.

#include <cstddef>

namespace impetus::view {

inline constexpr int kFrameKind = 1;
inline constexpr std::size_t kFrameHeaderValues = 16;
inline constexpr std::size_t kBodyValues = 7;
inline constexpr std::size_t kEndpointValues = 12;
inline constexpr std::size_t kPlaneValues = 6;
inline constexpr std::size_t kDentValues = 8;
inline constexpr std::size_t kToolValues = 21;
inline constexpr std::size_t kMaxClientMessageBytes = 4096;
// A mesh of 10^5 triangles is a scene message of about 3 MB, sent to each page as it connects; a finer one (a terrain)
// is coarsened to that many rather than hold up a page for seconds.
inline constexpr std::size_t kMaxViewMeshTriangles = 100'000;
inline constexpr double kMinReplaySpeed = 0.1;
inline constexpr double kMaxReplaySpeed = 10.0;

}  // namespace impetus::view

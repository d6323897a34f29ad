#pragma once
// LCM channel names (ARCHITECTURE.md, "Data flow and channels"). Nodes take their
// channels from the command line with these as defaults.
namespace aerie::channels {

inline constexpr const char* kCamLeft = "CAM_LEFT";      // aerie.image_t
inline constexpr const char* kCamRight = "CAM_RIGHT";    // aerie.image_t
inline constexpr const char* kCamStereo = "CAM_STEREO";  // aerie.stereo_image_t (rectified)
inline constexpr const char* kCamMono = "CAM_MONO";      // aerie.image_t
inline constexpr const char* kCamDown = "CAM_DOWN";      // aerie.image_t, landing camera (intrinsics in metadata)
inline constexpr const char* kImu = "IMU";               // aerie.imu_t
inline constexpr const char* kGtPose = "GT_POSE";        // aerie.gt_pose_t
inline constexpr const char* kGtTrack = "GT_TRACK";      // aerie.gt_box_t
inline constexpr const char* kTrack = "TRACK";           // aerie.track_t
inline constexpr const char* kTrackCmd = "TRACK_CMD";    // aerie.track_cmd_t
inline constexpr const char* kTargetPose = "TARGET_POSE";  // aerie.target_pose_t
inline constexpr const char* kVoPose = "VO_POSE";        // aerie.pose_t
inline constexpr const char* kNavState = "NAV_STATE";    // aerie.nav_state_t (VO + IMU EKF)
inline constexpr const char* kVoDepth = "VO_DEPTH";      // aerie.spherical_depth_t
inline constexpr const char* kMapOctomap = "MAP_OCTOMAP";  // aerie.octomap_t
inline constexpr const char* kMapQuery = "MAP_QUERY";    // aerie.map_query_t
inline constexpr const char* kMapResponse = "MAP_RESPONSE";  // aerie.map_response_t (default reply channel)
inline constexpr const char* kMapCmd = "MAP_CMD";        // aerie.map_cmd_t
inline constexpr const char* kCtrlCmd = "CTRL_CMD";      // aerie.control_cmd_t
inline constexpr const char* kPilotCmd = "PILOT_CMD";    // aerie.pilot_cmd_t (operator -> pilot)
inline constexpr const char* kPilotState = "PILOT_STATE";  // aerie.pilot_state_t
inline constexpr const char* kSimState = "SIM_STATE";    // aerie.sim_state_t (simulator ground truth)
inline constexpr const char* kFlcParams = "FLC_PARAMS";  // aerie.flc_params_t
inline constexpr const char* kCeProgress = "CE_PROGRESS";  // aerie.ce_progress_t
inline constexpr const char* kLinkStats = "LINK_STATS";  // aerie.link_stats_t
inline constexpr const char* kAutopilotState = "AUTOPILOT_STATE";  // aerie.autopilot_state_t (aerie-mavlink)
inline constexpr const char* kStatusPrefix = "STATUS_";  // aerie.process_status_t, STATUS_<NODE>

}  // namespace aerie::channels

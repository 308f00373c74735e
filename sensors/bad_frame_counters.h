#pragma once
// Counters of everything the scan assembler rejected or repaired, since start. A plain
// struct of integers so the bridge can copy it into its status message.

#include <cstdint>
#include <string>

namespace sedbridge::sensors {

/// CAN controller state from its error frames (BadFrameCounters::bus_state).
enum BusState : int64_t { kBusErrorActive = 0, kBusErrorPassive = 1, kBusOff = 2 };

struct BadFrameCounters {
  int64_t frames = 0;           ///< frames pushed into the assembler
  int64_t frames_used = 0;      ///< frames whose samples went into a scan
  // Frames rejected outright.
  int64_t unknown_id = 0;       ///< id not in the profile (other traffic on the bus)
  int64_t wrong_length = 0;     ///< DLC/length differs from the profile
  int64_t wrong_frame_type = 0; ///< classic vs FD mismatch
  int64_t bad_frame_index = 0;  ///< frame_index field out of range
  int64_t remote_frames = 0;    ///< remote requests with a sensor id
  int64_t error_frames = 0;     ///< controller error frames
  int64_t other_interface = 0;  ///< from another CAN interface than the sensor's
  int64_t duplicates = 0;       ///< same slot, same payload, again within half a scan period
  int64_t stale_frames = 0;     ///< frame of an older scan (counter behind, or time before
                                ///< the current scan began)
  // Frames accepted but notable.
  int64_t reordered = 0;        ///< slot arrived after a higher slot of the same scan
  // Scans.
  int64_t scans_complete = 0;
  int64_t scans_partial = 0;    ///< emitted with missing slots
  int64_t missing_frames = 0;   ///< slots missing in partial scans
  int64_t scans_dropped = 0;    ///< gaps in the sensor's scan counter
  // Taxel values (summed over scans).
  int64_t saturated_values = 0;
  int64_t nonfinite_values = 0;
  int64_t stale_taxels = 0;
  // Controller state (from error frames).
  int64_t bus_off_events = 0;        ///< error frames with CAN_ERR_BUSOFF
  int64_t error_passive_events = 0;  ///< controller error frames reporting RX/TX error-passive
  int64_t bus_state = kBusErrorActive;  ///< latest BusState; back to active on CAN_ERR_RESTARTED
                                        ///< or CAN_ERR_CRTL_ACTIVE

  /// Frames rejected for any reason.
  int64_t rejected() const {
    return unknown_id + wrong_length + wrong_frame_type + bad_frame_index + remote_frames +
           error_frames + duplicates + stale_frames + other_interface;
  }
};

/// Multi-line human-readable report ("  unknown_id           3"), zero counters included.
std::string FormatCounters(const BadFrameCounters& c);

}  // namespace sedbridge::sensors

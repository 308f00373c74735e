#include "sensors/frame_source.h"

#include <linux/can/error.h>

namespace sedbridge::sensors {

void CountErrorFrame(const Frame& f, FrameSourceStats* s) {
  ++s->error_frames;
  const uint32_t cls = f.id;
  bool known = false;
  if (cls & CAN_ERR_BUSOFF) ++s->bus_off, known = true;
  if (cls & CAN_ERR_RESTARTED) ++s->restarted, known = true;
  if (cls & CAN_ERR_CRTL) {
    known = true;
    // Controller status lives in data[1] (only meaningful when the frame carries it).
    const uint8_t ctrl = f.len > 1 ? f.data[1] : 0;
    if (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) ++s->controller_overflow;
    if (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) ++s->error_passive;
    if (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) ++s->error_warning;
  }
  const uint32_t others = CAN_ERR_TX_TIMEOUT | CAN_ERR_LOSTARB | CAN_ERR_PROT | CAN_ERR_TRX |
                          CAN_ERR_ACK | CAN_ERR_BUSERROR;
  if ((cls & others) || !known) ++s->other_errors;
}

}  // namespace sedbridge::sensors

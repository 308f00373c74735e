#include "display/actuator_output.h"

#include <stdexcept>

#include "display/csv_actuator_output.h"
#include "display/serial_actuator_output.h"

namespace sedbridge::display {

std::unique_ptr<ActuatorOutput> MakeActuatorOutput(const std::string& spec, std::size_t actuators,
                                                   const std::string& unit) {
  if (spec == "stdout") return std::make_unique<CsvActuatorOutput>("", actuators, unit);
  if (spec.rfind("csv:", 0) == 0 && spec.size() > 4)
    return std::make_unique<CsvActuatorOutput>(spec.substr(4), actuators, unit);
  if (spec.rfind("serial:", 0) == 0 && spec.size() > 7) {
    std::string device = spec.substr(7);
    int baud = 115200;
    const std::size_t colon = device.rfind(':');
    if (colon != std::string::npos) {
      try {
        baud = std::stoi(device.substr(colon + 1));
      } catch (const std::exception&) {
        throw std::invalid_argument("bad baud rate in '" + spec + "'");
      }
      device.resize(colon);
    }
    return std::make_unique<SerialActuatorOutput>(device, baud);
  }
  throw std::invalid_argument("output must be stdout, csv:PATH or serial:DEVICE[:BAUD] (got '" + spec + "')");
}

}  // namespace sedbridge::display

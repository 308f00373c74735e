#include "display/serial_actuator_output.h"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace sedbridge::display {
namespace {

speed_t BaudConstant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
  }
  throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
}

}  // namespace

std::string FormatSerialLine(const ActuatorFrame& f) {
  std::string body = "D," + std::to_string(f.sequence) + "," +
                     std::to_string((f.stale ? 1 : 0) | (f.fault ? 2 : 0) | (f.shutdown ? 4 : 0)) + "," +
                     std::to_string(f.value.size());
  char num[32];
  for (double v : f.value) {
    std::snprintf(num, sizeof num, ",%.3f", v);
    body += num;
  }
  unsigned char sum = 0;
  for (char c : body) sum ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", sum);
  return "$" + body + tail;
}

SerialActuatorOutput::SerialActuatorOutput(const std::string& device, int baud) : device_(device), baud_(baud) {
  const speed_t speed = BaudConstant(baud);
  fd_ = ::open(device.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error("cannot open serial port '" + device + "': " + std::strerror(errno));
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) {
    ::close(fd_);
    throw std::runtime_error("'" + device + "' is not a serial port: " + std::strerror(errno));
  }
  ::cfmakeraw(&tio);  // 8 data bits, no parity, no echo, no line editing
  tio.c_cflag &= ~(CSTOPB | CRTSCTS);
  tio.c_cflag |= CLOCAL | CREAD;
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
    ::close(fd_);
    throw std::runtime_error("cannot configure '" + device + "': " + std::strerror(errno));
  }
}

SerialActuatorOutput::~SerialActuatorOutput() {
  if (fd_ >= 0) ::close(fd_);
}

bool SerialActuatorOutput::Write(const ActuatorFrame& frame) {
  const std::string line = FormatSerialLine(frame);
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += std::size_t(n);
  }
  return true;
}

std::string SerialActuatorOutput::Describe() const {
  return "serial " + device_ + " at " + std::to_string(baud_) + " baud";
}

}  // namespace sedbridge::display

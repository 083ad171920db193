#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "stewart/hw_bridge/transport.h"

namespace stewart::hw {
namespace {

speed_t BaudConstant(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    case 1000000:
      return B1000000;
    case 2000000:
      return B2000000;
    case 3000000:
      return B3000000;
    default:
      return 0;
  }
}

void MakeRaw(int fd, speed_t speed, const std::string& what) {
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) {
    throw std::runtime_error(what + ": tcgetattr: " + std::strerror(errno));
  }
  cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (speed != 0 && (cfsetispeed(&tio, speed) != 0 || cfsetospeed(&tio, speed) != 0)) {
    throw std::runtime_error(what + ": cannot set the baud rate");
  }
  if (tcsetattr(fd, TCSANOW, &tio) != 0) {
    throw std::runtime_error(what + ": tcsetattr: " + std::strerror(errno));
  }
}

}  // namespace

FdTransport::FdTransport(int fd, std::string description)
    : fd_(fd), description_(std::move(description)) {}

FdTransport::~FdTransport() {
  if (fd_ >= 0) close(fd_);
}

FdStreamTransport::FdStreamTransport(int fd, std::string description)
    : FdTransport(fd, std::move(description)) {}

bool FdStreamTransport::Send(const uint8_t* data, std::size_t size) {
  std::size_t sent = 0;
  int spins = 0;
  while (sent < size) {
    const ssize_t n = write(fd_, data + sent, size - sent);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return false;
    // Output buffer full (nobody reading): drop a whole frame at once, but
    // once started, wait briefly rather than cut one in half.
    if (sent == 0) return false;
    pollfd p{fd_, POLLOUT, 0};
    if (++spins > 5 || poll(&p, 1, 1) < 0) return false;
  }
  return true;
}

long FdStreamTransport::Receive(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  const int ready = poll(&p, 1, timeout_ms);
  if (ready < 0) return errno == EINTR ? 0 : -1;
  if (ready == 0) return 0;
  if ((p.revents & POLLIN) == 0) return -1;  // hangup or error only
  const ssize_t n = read(fd_, buffer, capacity);
  if (n < 0) return (errno == EAGAIN || errno == EINTR) ? 0 : -1;
  return static_cast<long>(n);
}

std::unique_ptr<FdStreamTransport> OpenSerial(const std::string& device, int baud) {
  const speed_t speed = BaudConstant(baud);
  if (speed == 0) {
    throw std::runtime_error("serial baud " + std::to_string(baud) + " is not supported");
  }
  const int fd = open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    throw std::runtime_error("cannot open serial device '" + device + "': " + std::strerror(errno));
  }
  auto transport = std::make_unique<FdStreamTransport>(
      fd, "serial " + device + " @ " + std::to_string(baud) + " baud");
  MakeRaw(fd, speed, device);
  tcflush(fd, TCIOFLUSH);
  return transport;
}

PtyDevice::PtyDevice() {
  const int master = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (master < 0) throw std::runtime_error(std::string("posix_openpt: ") + std::strerror(errno));
  master_ = std::make_unique<FdStreamTransport>(master, "pty master");
  if (grantpt(master) != 0 || unlockpt(master) != 0) {
    throw std::runtime_error(std::string("grantpt/unlockpt: ") + std::strerror(errno));
  }
  char name[128];
  if (ptsname_r(master, name, sizeof(name)) != 0) {
    throw std::runtime_error(std::string("ptsname_r: ") + std::strerror(errno));
  }
  slave_path_ = name;
  slave_fd_ = open(name, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (slave_fd_ < 0) {
    throw std::runtime_error("cannot open pty slave " + slave_path_ + ": " + std::strerror(errno));
  }
  MakeRaw(slave_fd_, 0, slave_path_);
  MakeRaw(master, 0, "pty master");
}

PtyDevice::~PtyDevice() {
  if (slave_fd_ >= 0) close(slave_fd_);
}

}  // namespace stewart::hw

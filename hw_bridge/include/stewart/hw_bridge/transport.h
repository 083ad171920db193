#pragma once
// Byte transports to the device: UDP datagrams (one frame per datagram) and
// a serial byte stream (termios; frames reassembled by StreamParser).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "stewart/hw_bridge/hw_bridge_config.h"

namespace stewart::hw {

class Transport {
 public:
  virtual ~Transport() = default;
  /// Sends all bytes; false on an error (counted by the caller, never fatal).
  virtual bool Send(const uint8_t* data, std::size_t size) = 0;
  /// Waits up to timeout_ms (0 = poll) and reads what is there: one datagram,
  /// or the available stream bytes. Returns bytes read, 0 on timeout, -1 on error.
  virtual long Receive(uint8_t* buffer, std::size_t capacity, int timeout_ms) = 0;
  /// True if one Receive() returns exactly one datagram.
  virtual bool datagram() const = 0;
  /// For poll() together with other sources.
  virtual int fd() const = 0;
  virtual std::string description() const = 0;
};

/// A transport on a file descriptor it owns (closed with it).
class FdTransport : public Transport {
 public:
  ~FdTransport() override;
  FdTransport(const FdTransport&) = delete;
  FdTransport& operator=(const FdTransport&) = delete;

  int fd() const override { return fd_; }
  std::string description() const override { return description_; }

 protected:
  FdTransport(int fd, std::string description);

  int fd_;
  std::string description_;
};

/// UDP bound to bind_host:bind_port, sending to peer_host:peer_port. Only
/// datagrams from the peer's address are accepted; others are counted in
/// foreign_datagrams(). Throws std::runtime_error naming the address.
class UdpTransport final : public FdTransport {
 public:
  UdpTransport(const std::string& bind_host, int bind_port, const std::string& peer_host,
               int peer_port);

  bool Send(const uint8_t* data, std::size_t size) override;
  long Receive(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  bool datagram() const override { return true; }
  uint64_t foreign_datagrams() const { return foreign_; }

 private:
  uint32_t peer_addr_ = 0;  // network order
  uint16_t peer_port_ = 0;  // network order
  uint64_t foreign_ = 0;
};

/// A byte stream on a file descriptor it owns (a tty or a pty master).
class FdStreamTransport : public FdTransport {
 public:
  FdStreamTransport(int fd, std::string description);

  bool Send(const uint8_t* data, std::size_t size) override;
  long Receive(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  bool datagram() const override { return false; }
};

/// Opens a serial device raw (8N1, no flow control, no echo) at `baud`.
/// Throws std::runtime_error naming the device and the reason.
std::unique_ptr<FdStreamTransport> OpenSerial(const std::string& device, int baud);

/// The host's end of the link hw_bridge.transport names: "serial" opens
/// serial_device, anything else binds UDP local_host:local_port towards
/// device_host:device_port.
std::unique_ptr<Transport> OpenHostTransport(const HwBridgeConfig& hw);

/// A pseudo-terminal pair: the master end as a transport (the emulator's
/// device side) and the slave path a SerialTransport opens. The slave is kept
/// open here in raw mode so nothing echoes before the host opens it.
class PtyDevice {
 public:
  PtyDevice();  ///< throws std::runtime_error
  ~PtyDevice();
  PtyDevice(const PtyDevice&) = delete;
  PtyDevice& operator=(const PtyDevice&) = delete;

  const std::string& slave_path() const { return slave_path_; }
  /// The master end; valid for the PtyDevice's lifetime.
  FdStreamTransport* master() { return master_.get(); }

 private:
  std::unique_ptr<FdStreamTransport> master_;
  int slave_fd_ = -1;
  std::string slave_path_;
};

}  // namespace stewart::hw

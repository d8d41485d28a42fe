/// @file
/// The serial transport of the vendor drivers' LineClient: a termios line in raw mode,
/// 8 data bits, no parity, one stop bit (8N1, what PI's E-873/C-867 and Attocube's ANC300 speak),
/// no flow control unless `flow=rtscts`, non-blocking so that every read and write waits in
/// poll() against the same deadline as the TCP client (line_client.cc). termios(3) and
/// tty_ioctl(4) are the references for each flag.

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/drivers/line_client.h"

namespace mc::drivers {
namespace {

speed_t speed_of(int baud) {
  switch (baud) {
    case 1200:
      return B1200;
    case 2400:
      return B2400;
    case 4800:
      return B4800;
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
    default:
      return B0;  // parse_connection admits only the rates above
  }
}

}  // namespace

void LineClient::open_serial(const SerialLine& line) {
  close();
  const std::string where = "the serial line " + excerpt(line.path);
  const speed_t speed = speed_of(line.baud);
  if (speed == B0) throw InvalidInput(where + ": unsupported baud " + std::to_string(line.baud));
  // O_NOCTTY: the controller's line never becomes this process's controlling terminal (a hang-up
  // would then signal us); O_NONBLOCK: every wait is poll()'s, with its deadline.
  const int fd = ::open(line.path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    throw InvalidInput("cannot open " + where + ": " + std::strerror(err) +
                       (err == ENOENT ? " (is the adapter plugged in? ls /dev/serial/by-id)" : ""));
  }
  auto refuse = [&](const std::string& why) {
    ::close(fd);
    throw InvalidInput(where + ": " + why);
  };
  if (!::isatty(fd)) {
    struct stat st {};
    ::fstat(fd, &st);
    refuse(S_ISREG(st.st_mode) ? "a regular file, not a serial port (tty)" : "not a serial port (tty)");
  }
  // Exclusive: a second driver (or a terminal program) opening the same line fails with EBUSY
  // instead of interleaving its bytes with ours.
  if (::ioctl(fd, TIOCEXCL) != 0) refuse(std::string("cannot take it exclusively: ") + std::strerror(errno));
  termios t{};
  if (::tcgetattr(fd, &t) != 0) refuse(std::string("tcgetattr: ") + std::strerror(errno));
  ::cfmakeraw(&t);  // no echo, no line editing, no CR/LF translation, no signals, 8 bits
  t.c_cflag &= ~static_cast<tcflag_t>(PARENB | CSTOPB | CSIZE | CRTSCTS);
  t.c_cflag |= CS8 | CREAD | CLOCAL;  // CLOCAL: no modem (carrier) lines on a controller's cable
  if (line.rtscts) t.c_cflag |= CRTSCTS;
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);  // XON/XOFF would eat 0x11/0x13
  // VMIN=1, VTIME=0 with O_NONBLOCK: read() returns what is there or EAGAIN, never 0 for "nothing
  // yet" (with VMIN=0 a quiet line would read as a hang-up).
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  if (::cfsetispeed(&t, speed) != 0 || ::cfsetospeed(&t, speed) != 0)
    refuse("cannot set " + std::to_string(line.baud) + " baud");
  if (::tcsetattr(fd, TCSANOW, &t) != 0) refuse(std::string("tcsetattr: ") + std::strerror(errno));
  // tcsetattr succeeds if any one change took: read back what the driver really applied.
  termios applied{};
  if (::tcgetattr(fd, &applied) != 0 || ::cfgetospeed(&applied) != speed ||
      (applied.c_cflag & (CSIZE | PARENB | CSTOPB)) != CS8)
    refuse("the port did not take " + std::to_string(line.baud) + " baud 8N1");
  ::tcflush(fd, TCIOFLUSH);  // what a previous session left on the line
  fd_ = fd;
  tty_ = true;
  pending_.clear();
  error_.clear();
}

}  // namespace mc::drivers

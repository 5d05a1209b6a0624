// Reorders packets for the fault tests where the kernel has no netem: receives the packets an iptables
// NFQUEUE rule hands it (`iptables -A INPUT -d 224.0.0.0/4 -j NFQUEUE --queue-num N`, in the test's private
// network namespace) and accepts them in arrival order, except that a fraction of them is held back and
// accepted only after the next 1 to --max-delay packets (a later packet overtakes it, as on a LAN with
// several paths or a Wi-Fi retry). In the INPUT hook the kernel has already reassembled IP fragments, so
// what is reordered is whole UDP datagrams (an LCM message or one of its fragments). Seeded: the same
// packet sequence is reordered the same way. Prints what it did on SIGINT / SIGTERM.
//   reorder-queue --queue N --percent P [--max-delay K] [--seed S]
// glibc's netinet/in.h before the kernel's headers (they then leave out what glibc defines).
#include <netinet/in.h>
#include <sys/socket.h>
#include <linux/netfilter.h>
#include <libnetfilter_queue/libnetfilter_queue.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <random>
#include <string>

namespace {

volatile std::sig_atomic_t g_stop = 0;

struct Held {
  std::uint32_t id;
  int release_after;  // packets still to pass before it
};

struct Reorderer {
  nfq_q_handle* queue = nullptr;
  double fraction = 0.01;
  int max_delay = 4;
  std::mt19937_64 rng;
  std::deque<Held> held;
  long long packets = 0, reordered = 0;

  void accept(std::uint32_t id) { nfq_set_verdict(queue, id, NF_ACCEPT, 0, nullptr); }

  void onPacket(std::uint32_t id) {
    ++packets;
    if (std::uniform_real_distribution<double>(0.0, 1.0)(rng) < fraction) {
      held.push_back({id, std::uniform_int_distribution<int>(1, max_delay)(rng)});
      ++reordered;
      return;
    }
    accept(id);
    for (auto it = held.begin(); it != held.end();) {
      if (--it->release_after <= 0) {
        accept(it->id);
        it = held.erase(it);
      } else {
        ++it;
      }
    }
  }
};

int onQueued(nfq_q_handle*, nfgenmsg*, nfq_data* data, void* self) {
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(data);
  if (header) static_cast<Reorderer*>(self)->onPacket(ntohl(header->packet_id));
  return 0;
}

void stop(int) { g_stop = 1; }

}  // namespace

int main(int argc, char** argv) {
  int queue_num = 0;
  Reorderer r;
  std::uint64_t seed = 1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--queue") queue_num = std::atoi(argv[i + 1]);
    else if (key == "--percent") r.fraction = std::atof(argv[i + 1]) / 100.0;
    else if (key == "--max-delay") r.max_delay = std::max(1, std::atoi(argv[i + 1]));
    else if (key == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
    else {
      std::fprintf(stderr, "usage: reorder-queue --queue N --percent P [--max-delay K] [--seed S]\n");
      return 2;
    }
  }
  r.rng.seed(seed);
  nfq_handle* handle = nfq_open();
  if (!handle) {
    std::perror("reorder-queue: nfq_open");
    return 1;
  }
  r.queue = nfq_create_queue(handle, static_cast<std::uint16_t>(queue_num), &onQueued, &r);
  // Only the packet id is needed: no payload is copied to user space.
  if (!r.queue || nfq_set_mode(r.queue, NFQNL_COPY_META, 0) < 0) {
    std::perror("reorder-queue: cannot bind the queue");
    return 1;
  }
  // Without SA_RESTART, so that a signal ends the blocking recv() below.
  struct sigaction action {};
  action.sa_handler = stop;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::fprintf(stderr, "reorder-queue: queue %d, %.2f %% held back for 1-%d packets\n", queue_num, 100 * r.fraction, r.max_delay);
  const int fd = nfq_fd(handle);
  char buf[65536] __attribute__((aligned));
  while (!g_stop) {
    const ssize_t n = recv(fd, buf, sizeof(buf), 0);
    if (n < 0) {
      if (errno == EINTR || errno == ENOBUFS) continue;  // ENOBUFS: the kernel dropped queued packets
      std::perror("reorder-queue: recv");
      break;
    }
    nfq_handle_packet(handle, buf, static_cast<int>(n));
  }
  for (const Held& h : r.held) r.accept(h.id);
  std::printf("reorder-queue: %lld packets, %lld held back and overtaken\n", r.packets, r.reordered);
  std::fflush(stdout);
  nfq_destroy_queue(r.queue);
  nfq_close(handle);
  return 0;
}

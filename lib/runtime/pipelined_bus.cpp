#include "runtime/pipelined_bus.hpp"

#include <algorithm>
#include <stdexcept>

namespace adit::runtime {
namespace {

// Upstream input traces handed to the worker at once (one wake-up per batch, not per IMU sample), and the
// batches that may wait for it before the upstream thread waits in turn (bounds the memory of running ahead).
constexpr std::size_t kBatchTraces = 16;
constexpr std::size_t kMaxBatches = 8;

}  // namespace

std::size_t pipelineSplit(const std::vector<Node*>& nodes) {
  for (std::size_t s = 1; s < nodes.size(); ++s) {
    bool feeds_back = false;
    for (std::size_t d = s; d < nodes.size() && !feeds_back; ++d)
      for (const std::string& channel : nodes[d]->outputChannels())
        for (std::size_t u = 0; u < s && !feeds_back; ++u) feeds_back = nodes[u]->isInput(channel);
    if (!feeds_back) return s;
  }
  return 0;
}

// Where a node's publications go: collected (upstream), or observed and queued for delivery (downstream).
class PipelinedBus::Collector : public Sink {
 public:
  explicit Collector(std::vector<Message>& out) : out_(out) {}
  void publish(const std::string& channel, const Bytes& data, std::int64_t utime) override {
    out_.push_back({channel, std::make_shared<const Bytes>(data), utime});
  }

 private:
  std::vector<Message>& out_;
};

// Without finish() (the caller stopped on an error): what the worker has not started is abandoned.
PipelinedBus::~PipelinedBus() {
  if (!worker_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    batches_.clear();
  }
  changed_.notify_all();
  worker_.join();
}

void PipelinedBus::add(Node& node) {
  if (started_) throw std::logic_error("PipelinedBus: nodes are added before the first input");
  nodes_.push_back(&node);
  serial_.add(node);
}

void PipelinedBus::observe(Observer observer) {
  observers_.push_back(observer);
  serial_.observe(std::move(observer));
}

void PipelinedBus::start() {
  if (started_) return;
  started_ = true;
  split_ = pipelined_ ? pipelineSplit(nodes_) : 0;
  if (split_ > 0) worker_ = std::thread([this] { workerLoop(); });
}

void PipelinedBus::inject(const std::string& channel, const Bytes& data, std::int64_t utime) {
  start();
  if (split_ == 0) return serial_.inject(channel, data, utime);
  rethrow();
  Trace trace = runUpstream({{channel, std::make_shared<const Bytes>(data), utime}}, false);
  const bool upstream_published =
      std::any_of(trace.published.begin(), trace.published.end(), [](const auto& p) { return !p.empty(); });
  hand(std::move(trace), upstream_published);  // a sweep's results go at once, IMU samples in batches
}

// The one-threaded bus over the upstream nodes alone: their deliveries do not depend on the downstream ones.
PipelinedBus::Trace PipelinedBus::runUpstream(std::vector<Message> roots, bool observe_roots) {
  Trace trace;
  std::deque<Message> queue(roots.begin(), roots.end());
  trace.roots = std::move(roots);
  trace.observe_roots = observe_roots;
  while (!queue.empty()) {
    const Message m = std::move(queue.front());
    queue.pop_front();
    std::vector<Message>& published = trace.published.emplace_back();
    Collector sink(published);
    for (std::size_t i = 0; i < split_; ++i)
      if (nodes_[i]->isInput(m.channel)) nodes_[i]->deliver(m.channel, m.data->data(), m.data->size(), sink);
    queue.insert(queue.end(), published.begin(), published.end());
  }
  return trace;
}

void PipelinedBus::hand(Trace trace, bool flush) {
  batch_.push_back(std::move(trace));
  if (!flush && batch_.size() < kBatchTraces) return;
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return batches_.size() < kMaxBatches || error_; });
  batches_.push_back(std::move(batch_));
  batch_.clear();
  lock.unlock();
  changed_.notify_all();
}

void PipelinedBus::workerLoop() {
  for (;;) {
    std::vector<Trace> batch;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [&] { return !batches_.empty() || closed_; });
      if (batches_.empty()) return;
      batch = std::move(batches_.front());
      batches_.pop_front();
    }
    changed_.notify_all();
    try {
      for (const Trace& trace : batch) replay(trace);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = std::current_exception();
      batches_.clear();
      closed_ = true;
      changed_.notify_all();
      return;
    }
  }
}

void PipelinedBus::notify(const Message& m) const {
  for (auto& observer : observers_) observer(m.channel, *m.data, m.utime);
}

// The one-threaded bus's order over both groups: first in, first out; a message's upstream deliveries come
// first (upstream nodes precede downstream ones), their publications taken from the trace.
void PipelinedBus::replay(const Trace& trace) {
  Queue queue;
  for (const Message& m : trace.roots) {
    if (trace.observe_roots) notify(m);
    queue.emplace_back(m, true);
  }
  if (drainDownstream(queue, &trace) != trace.published.size())
    throw std::logic_error("PipelinedBus: upstream trace out of step");
}

// Returns how many of the trace's records (one per upstream message delivered) it used.
std::size_t PipelinedBus::drainDownstream(Queue& queue, const Trace* trace) {
  std::size_t next_pop = 0;
  std::vector<Message> published;
  Collector sink(published);
  while (!queue.empty()) {
    const auto [m, upstream] = std::move(queue.front());
    queue.pop_front();
    if (upstream) {
      if (!trace || next_pop >= trace->published.size()) throw std::logic_error("PipelinedBus: upstream trace too short");
      for (const Message& p : trace->published[next_pop]) {
        notify(p);
        queue.emplace_back(p, true);
      }
      ++next_pop;
    }
    for (std::size_t i = split_; i < nodes_.size(); ++i) {
      if (!nodes_[i]->isInput(m.channel)) continue;
      published.clear();
      nodes_[i]->deliver(m.channel, m.data->data(), m.data->size(), sink);
      queueDownstream(published, queue);
    }
  }
  return next_pop;
}

// What a downstream node published: observed and queued for delivery. The cut is made from the advertised
// ports; a publication on any other port must not break it either.
void PipelinedBus::queueDownstream(const std::vector<Message>& published, Queue& queue) const {
  for (const Message& p : published) {
    for (std::size_t u = 0; u < split_; ++u)
      if (nodes_[u]->isInput(p.channel))
        throw std::logic_error("PipelinedBus: " + p.channel + " flows back to " + nodes_[u]->name());
    notify(p);
    queue.emplace_back(p, false);
  }
}

void PipelinedBus::finish() {
  start();
  if (split_ == 0) return serial_.finish();
  rethrow();
  for (std::size_t i = 0; i < split_; ++i) {
    std::vector<Message> published;
    Collector sink(published);
    nodes_[i]->finish(sink);
    hand(runUpstream(std::move(published), true), true);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
  worker_.join();
  rethrow();
  finishDownstream();
}

void PipelinedBus::finishDownstream() {
  for (std::size_t i = split_; i < nodes_.size(); ++i) {
    std::vector<Message> published;
    Collector sink(published);
    nodes_[i]->finish(sink);
    Queue queue;
    queueDownstream(published, queue);
    drainDownstream(queue, nullptr);
  }
}

void PipelinedBus::rethrow() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (error_) std::rethrow_exception(error_);
}

}  // namespace adit::runtime

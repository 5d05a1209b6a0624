// The lockstep bus (runtime/lockstep.hpp) on two threads, with the same deliveries in the same order and
// the same published messages in the same order: a replay's output does not change, only its speed.
//
// The nodes are cut where nothing flows back: an upstream group (feature stage, odometry) whose inputs never
// come from the downstream group (mapper, loop closer, relocaliser). The upstream nodes then see exactly what
// they would see in the one-threaded bus, whatever the downstream nodes do, so the caller's thread runs them
// ahead and records, for each message it delivers, what they published. A worker thread replays the
// one-threaded bus's first-in first-out order over both groups: an upstream message's deliveries are taken
// from the record, a downstream node's are made there. So the mapper of sweep n runs beside the feature
// stage and odometry of sweep n+1, and every observer (the output log) is called on the worker thread in the
// one-threaded order.
//
// Where no such cut exists (a stage subset whose outputs feed back, a single node) the bus runs one-threaded.
#pragma once

#include "runtime/lockstep.hpp"

#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

namespace adit::runtime {

// The first index s (0 < s < nodes.size()) such that no node from s on publishes on a channel that a node
// before s takes as input; 0 if there is none.
std::size_t pipelineSplit(const std::vector<Node*>& nodes);

class PipelinedBus {
 public:
  using Observer = LockstepBus::Observer;

  // pipelined = false: the one-threaded lockstep bus, for comparison.
  explicit PipelinedBus(bool pipelined = true) : pipelined_(pipelined) {}
  ~PipelinedBus();
  PipelinedBus(const PipelinedBus&) = delete;
  PipelinedBus& operator=(const PipelinedBus&) = delete;

  // Nodes in pipeline order, all of them before the first inject. Observers are called on one thread (the
  // worker when pipelined), in the one-threaded bus's order.
  void add(Node& node);
  void observe(Observer observer);

  void inject(const std::string& channel, const Bytes& data, std::int64_t utime);
  // End of input: finish every node in order; returns when everything is delivered and observed. An
  // exception thrown on the worker (an observer's) is rethrown here or by the next inject.
  void finish();

  // Index of the first downstream node; 0 while running one-threaded.
  std::size_t split() const { return split_; }

 private:
  struct Message {
    std::string channel;
    std::shared_ptr<const Bytes> data;
    std::int64_t utime = 0;
  };
  // What the upstream group did with one input (or one node's finish): the messages that start it and, for
  // every message it delivered in order, what the upstream nodes published.
  struct Trace {
    std::vector<Message> roots;
    bool observe_roots = false;  // a finish's publications are observed; an injected input is not
    std::vector<std::vector<Message>> published;
  };
  class Collector;
  using Queue = std::deque<std::pair<Message, bool>>;  // a message, and whether the upstream group delivered it

  void start();
  Trace runUpstream(std::vector<Message> roots, bool observe_roots);
  void hand(Trace trace, bool flush);
  void workerLoop();
  void replay(const Trace& trace);
  void finishDownstream();
  std::size_t drainDownstream(Queue& queue, const Trace* trace);
  void queueDownstream(const std::vector<Message>& published, Queue& queue) const;
  void notify(const Message& m) const;
  void rethrow();

  bool pipelined_;
  bool started_ = false;
  std::size_t split_ = 0;
  std::vector<Node*> nodes_;
  std::vector<Observer> observers_;
  LockstepBus serial_;

  std::vector<Trace> batch_;  // upstream traces not yet handed to the worker
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::vector<Trace>> batches_;
  bool closed_ = false;
  std::exception_ptr error_;
  std::thread worker_;
};

}  // namespace adit::runtime

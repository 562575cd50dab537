#pragma once
// The node types a program knows: each a spec (its contract), a run
// function and, for a manual node type, its task behaviour (what its tasks
// show and how a submission is evaluated: manual_task.h). nodes/ fills the
// registry of the mmm executable; tests build their own with test node types.
//
//   struct DecimateMesh {
//     static NodeSpec spec();
//     static void run(NodeContext& context);
//   };
//   registry.add<DecimateMesh>();
//
//   struct LandmarkStation {  // manual: spec().manual()
//     static NodeSpec spec();
//     static void run(NodeContext& context);  // never called by the engine
//     static ManualTaskBehaviour task_behaviour();
//   };
//   registry.add<LandmarkStation>();

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/manual_task.h"
#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::workflow {

using RunFunction = std::function<void(NodeContext& context)>;

struct NodeType {
  NodeSpec spec;
  RunFunction run;
  ManualTaskBehaviour task;  // manual node types only (complete); empty otherwise
};

class NodeRegistry {
 public:
  // Throws InvalidInputError when a type of that name is already registered,
  // when a manual type comes without a complete task behaviour and when a
  // computing type comes with one.
  void add(NodeSpec spec, RunFunction run, ManualTaskBehaviour task = {});
  template <class T>
  void add() {
    if constexpr (requires { T::task_behaviour(); }) {
      add(T::spec(), &T::run, T::task_behaviour());
    } else {
      add(T::spec(), &T::run);
    }
  }

  // nullptr for an unknown name.
  [[nodiscard]] const NodeType* find(std::string_view name) const;
  // All types, sorted by name.
  [[nodiscard]] std::vector<const NodeType*> all() const;
  // Names close to `name` (edit distance <= 2 or a shared prefix), for hints.
  [[nodiscard]] std::vector<std::string> similar_names(std::string_view name) const;

 private:
  std::map<std::string, NodeType, std::less<>> types_;
};

}  // namespace mmm::workflow

#pragma once
// The node types a program knows: each a spec (its contract) and a run
// function. nodes/ fills the registry of the mmm executable; tests build
// their own with test node types.
//
//   struct DecimateMesh {
//     static NodeSpec spec();
//     static void run(NodeContext& context);
//   };
//   registry.add<DecimateMesh>();

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::workflow {

using RunFunction = std::function<void(NodeContext& context)>;

struct NodeType {
  NodeSpec spec;
  RunFunction run;
};

class NodeRegistry {
 public:
  // Throws InvalidInputError when a type of that name is already registered.
  void add(NodeSpec spec, RunFunction run);
  template <class T>
  void add() {
    add(T::spec(), &T::run);
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

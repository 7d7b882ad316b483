// The JSON types of a glTF 2.0 document, checked before tinygltf reads it. tinygltf treats a
// property of the wrong type as absent: a node `"translation": [0, "x", 0]` became no
// translation at all, silently. Here every property photonlab reads, and the core schema's
// structural ones, must have the schema's type (number, integer index ≥ 0, string, boolean,
// object, array of so many numbers), or the load fails naming the element, e.g.
//   nodes[1].translation[1]: must be a number, got a string.
// Unknown properties and extensions are not photonlab's business and pass.
#pragma once
#include <string>

namespace pl {

// `json` is the document's JSON text (a .gltf file, or a .glb's JSON chunk). Returns "" when
// every checked property has its type, else "ELEMENT: what is wrong" for the first that does
// not. Text that is not JSON passes (the glTF parser reports it).
std::string checkGltfTypes(const std::string& json);

}  // namespace pl

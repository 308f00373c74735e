#pragma once
// Declares a class neither copyable nor movable (Drake's DRAKE_NO_COPY_NO_MOVE_NO_ASSIGN).
// For classes that hold pointers or references into their own members (a matrix's value
// pointer, a solver's factorization, a term's slots cached from a sibling): an implicit
// copy or move would leave the new object pointing at the old one's buffers.
// Use inside the class body, in its public section:
//   class SystemMatrix {
//    public:
//     SEDBRIDGE_NO_COPY_NO_MOVE(SystemMatrix)
//     SystemMatrix() = default;

#define SEDBRIDGE_NO_COPY_NO_MOVE(Class)     \
  Class(const Class&) = delete;              \
  Class& operator=(const Class&) = delete;   \
  Class(Class&&) = delete;                   \
  Class& operator=(Class&&) = delete;

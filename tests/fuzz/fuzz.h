/* What the libFuzzer harnesses of tests/fuzz share (common.c): one PETSc session per process, a
 * silent error handler, and a directory of their own for the files the readers open. */
#pragma once

#include <stddef.h>
#include <stdint.h>
#include <petscsys.h>

/* SLEPc and PETSc once (from LLVMFuzzerInitialize), perilin's registries, PeriErrorCapture pushed:
 * an input error is an outcome, kept and not printed. Returns 0 on success, as libFuzzer wants. */
int FuzzInitialize(void);
/* The fuzzer's directory (removed at exit). */
const char *FuzzDir(void);
/* Writes data into FuzzDir()/name; path receives the file's path. Non-zero when it cannot. */
int FuzzWriteFile(const char name[], const uint8_t *data, size_t size, char path[], size_t len);
/* An input's outcome: 0, or an error with its message (PeriErrorFirst); both are normal. Forgets
 * the message for the next input. With FUZZ_VERBOSE set, prints it (to see what the inputs reach). */
void FuzzOutcome(PetscErrorCode);

// The ADB probability model lands here.

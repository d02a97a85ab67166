"""What a user reads: run folders, CSV, text and figures (functions take ax=None and return
the axes; nothing here picks a matplotlib backend). Imports study and everything below."""

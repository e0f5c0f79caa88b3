-- whitted's language server in Neovim 0.7 and later, with the built-in client: `.scene`
-- files get the `whitted` filetype and one `whitted lsp` server per Neovim. Source this file
-- from your init.lua (`dofile("/path/to/whitted.lua")`) or copy it there. Set
-- `vim.g.whitted_command` to the binary's path when `whitted` is not on the PATH.
-- tests/integration/neovim.rs runs Neovim with exactly this file.

-- (Neovim 0.7's `vim.filetype.add` is opt-in, so the filetype comes from an autocommand.)
vim.api.nvim_create_autocmd({ "BufRead", "BufNewFile" }, {
  pattern = "*.scene",
  command = "setfiletype whitted",
})

local client_id = nil

vim.api.nvim_create_autocmd("FileType", {
  pattern = "whitted",
  callback = function(args)
    local config = {
      name = "whitted",
      cmd = { vim.g.whitted_command or "whitted", "lsp" },
      root_dir = vim.fn.getcwd(),
    }
    if vim.lsp.start then
      -- Neovim 0.8 and later: reuses a running server with the same name and root.
      vim.lsp.start(config)
      return
    end
    if client_id == nil then
      client_id = vim.lsp.start_client(config)
    end
    if client_id ~= nil then
      vim.lsp.buf_attach_client(args.buf, client_id)
    end
  end,
})
